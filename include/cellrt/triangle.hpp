// Triangles and the watertight ray-triangle test (Woop, Benthin, Wald: "Watertight Ray/Triangle
// Intersection", JCGT 2(1), 2013). It is the one triangle kernel of cellrt: brute force and every
// acceleration structure call it, so equal inputs give bit-equal t on every path.
//
// Why watertight: the test shears and scales the triangle into a space where the ray is the +z
// axis through the origin, then evaluates the three 2D edge functions. Neighbouring triangles share
// the exact same edge-function value for a shared edge (same vertices, same arithmetic), so a ray
// through an edge or a vertex is inside at least one of them. Edge values of exactly zero are
// recomputed in double precision (section 3 of the paper) so that the sign of a tiny value is right.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>

#if defined(__SSE2__) && !defined(__CUDA_ARCH__)
#include <emmintrin.h>
#define CELLRT_SSE2_TRIANGLE 1
#endif

#include "cellrt/box.hpp"
#include "cellrt/host_device.hpp"
#include "cellrt/ray.hpp"

namespace cellrt {

struct Triangle {
    Vec3 v0, v1, v2;

    CELLRT_HD Box3 bounds() const {
        Box3 b;
        b.extend(v0);
        b.extend(v1);
        b.extend(v2);
        return b;
    }
    CELLRT_HD Vec3 geometric_normal() const { return cross(v1 - v0, v2 - v0); }
    friend bool operator==(const Triangle&, const Triangle&) = default;
};
static_assert(sizeof(Triangle) == 36);

// Throws cellrt::Error "triangle I has a non-finite coordinate" for the first triangle with a NaN or
// infinite coordinate: bounds, split planes and Embree's buffers have no meaning for one.
void check_finite(std::span<const Triangle> triangles);

// Per-ray constants of the test, computed once per ray (section 2 of the paper).
struct WatertightRay {
    Vec3 org;
    int kx = 0, ky = 1, kz = 2;
    float sx = 0.f, sy = 0.f, sz = 0.f;

    // Of the traced direction (ray.hpp, traced_direction: subnormal components as zeros), as every
    // traversal's.
    CELLRT_HD explicit WatertightRay(const Ray& r) : WatertightRay(r.org, traced_direction(r)) {}
    // From an origin and traced_direction(r) of a valid ray r, already made (TraversalRay makes it
    // once for both); a raw direction would not be the ray every path traces.
    CELLRT_HD static WatertightRay of_traced(const Vec3& o, const Vec3& traced) { return WatertightRay(o, traced); }

private:
    CELLRT_HD WatertightRay(const Vec3& o, const Vec3& traced) : org(o) {
        kz = max_axis(traced);
        kx = kz == 2 ? 0 : kz + 1;
        ky = kx == 2 ? 0 : kx + 1;
        if (traced[kz] < 0.f) std::swap(kx, ky);  // keeps the winding, so the sign test is orientation-free
        sx = traced[kx] / traced[kz];
        sy = traced[ky] / traced[kz];
        sz = 1.f / traced[kz];
    }
};

// Whether the test's determinant is a normal float, neither zero, subnormal nor infinite (NaN fails).
CELLRT_HD inline bool det_in_range(float det) {
    const float a = std::fabs(det);
    return a >= kLeastNormal && a < kInfinity;
}

// An edge function recomputed in double precision, where its float value is exactly zero: the
// products of floats are exact in double and their difference is correctly signed. Rounded back to
// float it may still be zero (below half the least subnormal): its sign is then kept in the least
// subnormal, so that the sign test sees the side the double found. Lost, a ray 1e-35 off an edge of
// a 1e-10 triangle counted as on the edge: brute force took it, every structure's box test culled
// it (found by audit, 2026-12-07).
CELLRT_HD inline float edge_in_double(float a, float b, float c, float d) {
    const double e = double(a) * double(b) - double(c) * double(d);
    const float f = static_cast<float>(e);
    if (f != 0.f || e == 0.0) return f;
    return e > 0.0 ? kLeastSubnormal : -kLeastSubnormal;
}

// Hits whose t the float test cannot place. Woop et al.'s t is the depth of a barycentric mean of
// the vertices; where the edge functions cancel (a sliver, a triangle of zero area that rounding
// gave a determinant, a triangle seen at a grazing angle), their rounding errors move that point
// along the triangle, and t with it, by more than the structures' margins allow (kernel/traversal.hpp:
// 2^-16 of the scene's reach). Brute force then took hits at points off the ray that every structure
// culled (found by audit, 2026-12-07). An edge function's error is a few ulps of the products of the
// sheared coordinates, at most `lateral` (their largest magnitude) squared or `lateral` times their
// unsheared size; over det it moves t by as many ulps times the triangle's depth range `depth` over
// det / `lateral`. Where lateral * depth passes kIllConditioned * |det|, t is taken again in double
// precision (refined_t). The bound is measured, not proved: of 109,751 hits on slivers of widths
// from 1e-1 to 1e-7 of their length, half of them on rays grazing their plane, the float t of the
// 16,817 below 64 lay at most 0.05 of the least margin off the triangle, of those below 256 up to
// 0.35, beyond 4096 up to 10^5 times (docs/figures/exact_hits_2026-12-07). Healthy hits stay far
// below: a triangle seen at 45 degrees gives about 1, at 5 degrees about 11; of Sponza's camera
// rays' hits 2.7 % pass 64.
inline constexpr float kIllConditioned = 64.f;

// Whether a hit with these magnitudes needs refined_t. The same operations in the same order on
// every path (the scalar test, SSE2's, the lanes'), so that every path makes the same choice.
CELLRT_HD inline bool ill_conditioned(float lateral, float depth, float det) {
    // Scaled on the left, exactly (a power of two): 64 |det| would overflow from |det| = 2^122 on.
    return (lateral * depth) * (1.f / kIllConditioned) > std::fabs(det);
}

// Whether T (big_t, t times det), the sum of the three terms e_k z_k, lost its value to underflow:
// T grows as the cube of the scene's size over the direction's, and on triangles some 1e-16 across
// and away along a unit direction every term is subnormal or zero. T of zero had lost its sign: a
// triangle just behind the origin was hit at t = -0, which tnear = 0 admits, on every path, before
// the triangle really in front (found by audit, 2026-12-07). Such a hit's t is taken again in double
// precision, which has the range. Terms of normal size that cancel to zero are left alone: that is
// a ray starting on the triangle (t = 0 exactly, as brute force has it), where double precision
// would give rounding noise of either sign. The terms are read only where T is tiny.
CELLRT_HD inline bool t_underflowed(float big_t, float t0, float t1, float t2) {
    return std::fabs(big_t) < kLeastNormal &&
           std::max(std::max(std::fabs(t0), std::fabs(t1)), std::fabs(t2)) < kLeastNormal;
}

// t of an ill-conditioned hit, in double precision: the depth of the triangle's point nearest the
// ray in the test's sheared frame (the ray the +z axis, t = depth * sz). Where the ray crosses the
// triangle that is the crossing; where the float test found it inside by rounding only (a grazing
// ray, a zero-area triangle rounding gave an area), the nearest point of an edge. That point lies on
// the triangle, within rounding of the ray, so every structure whose cells or boxes hold that part
// of the triangle reaches it within its margin: the crossing of the ray with the triangle's plane
// did not (on a grazing ray it lay 0.25 off a triangle 1 long, inside its box, outside the kd cells
// that hold it), and refusing such hits left holes where a zero-area triangle closes a T-junction
// (both found by audit, 2026-12-07). x, y, z are the vertices' coordinates on the axes kx, ky, kz,
// (ox, oy, oz) the origin's, (sx, sy, sz) the shear. u and v are that point's barycentrics (the
// weights of the second and third vertex), so that the point the hit names is the one t measures.
// False only where t is not finite.
[[gnu::noinline]] CELLRT_NOINLINE CELLRT_HD inline bool refined_t(const float (&x)[3], const float (&y)[3],
                                                                   const float (&z)[3], float ox, float oy, float oz,
                                                                   float sx, float sy, float sz, float& t, float& u,
                                                                   float& v) {
    double px[3], py[3], pz[3];  // the sheared frame: the ray at px = py = 0
    for (int k = 0; k < 3; ++k) {
        pz[k] = double(z[k]) - oz;
        px[k] = (double(x[k]) - ox) - sx * pz[k];
        py[k] = (double(y[k]) - oy) - sy * pz[k];
    }
    const double e[3] = {px[2] * py[1] - py[2] * px[1], px[0] * py[2] - py[0] * px[2], px[1] * py[0] - py[1] * px[0]};
    const double det = e[0] + e[1] + e[2];
    double w[3];  // the point's weights on the three vertices
    if (det != 0.0 && ((e[0] >= 0.0 && e[1] >= 0.0 && e[2] >= 0.0) || (e[0] <= 0.0 && e[1] <= 0.0 && e[2] <= 0.0))) {
        for (int k = 0; k < 3; ++k) w[k] = e[k] / det;
    } else {
        // The nearest point of the three edges (the first edge on a tie), k to k + 1.
        double nearest = 0.0;
        for (int k = 0; k < 3; ++k) {
            const int j = k == 2 ? 0 : k + 1;
            const double dx = px[j] - px[k], dy = py[j] - py[k], length2 = dx * dx + dy * dy;
            double along = length2 > 0.0 ? -(px[k] * dx + py[k] * dy) / length2 : 0.0;
            along = along < 0.0 ? 0.0 : (along > 1.0 ? 1.0 : along);
            const double qx = px[k] + along * dx, qy = py[k] + along * dy, distance2 = qx * qx + qy * qy;
            if (k == 0 || distance2 < nearest) {
                nearest = distance2;
                w[k] = 1.0 - along;
                w[j] = along;
                w[3 - k - j] = 0.0;
            }
        }
    }
    t = static_cast<float>((w[0] * pz[0] + w[1] * pz[1] + w[2] * pz[2]) * sz);
    u = static_cast<float>(w[1]);
    v = static_cast<float>(w[2]);
    return std::fabs(t) < kInfinity;
}

// Core of the test: on success writes t = T/det and the barycentrics, without any range check.
// Returns false when the ray misses the triangle's plane region or the triangle is degenerate
// (det == 0: zero area, or seen edge-on), and where the float arithmetic left its range: det not a
// normal float (the edge functions' products over- or underflowed: vertices some 1e19 or 1e-19 from
// the ray in the sheared space), or t not finite (T grows as the cube of the distance, and
// overflows some 1e13 away along a unit direction). t there is 0, noise or inf, which no
// structure's interval reaches (an interval from tnear past the scene box, say, culls what brute
// force would take): docs/HIT_SEMANTICS.md, "Known limits". An ill-conditioned hit's t is taken
// again (refined_t). Always inlined, as the
// per-ray set-up of the traversals (kernel/traversal.hpp): a unit that instantiates many kernels
// exhausts GCC's inlining budget, and an out-of-line call costs a kernel up to a tenth of its
// instructions (docs/BENCHMARKS.md).
[[gnu::always_inline]] CELLRT_HD inline bool intersect_unbounded_scalar(const WatertightRay& r, const Triangle& tri, float& t, float& u, float& v) {
    // The vertices' coordinates in ray order (x, y, z of v0, v1, v2: the nine floats of the
    // triangle's storage, read in place by index as Vec3::operator[] reads three).
    const float* c9 = reinterpret_cast<const float*>(&tri);
    const float ox = r.org[r.kx], oy = r.org[r.ky], oz = r.org[r.kz];
    const float a_kz = c9[r.kz] - oz, b_kz = c9[3 + r.kz] - oz, c_kz = c9[6 + r.kz] - oz;
    const float ax = (c9[r.kx] - ox) - r.sx * a_kz, ay = (c9[r.ky] - oy) - r.sy * a_kz;
    const float bx = (c9[3 + r.kx] - ox) - r.sx * b_kz, by = (c9[3 + r.ky] - oy) - r.sy * b_kz;
    const float cx = (c9[6 + r.kx] - ox) - r.sx * c_kz, cy = (c9[6 + r.ky] - oy) - r.sy * c_kz;
    float eu = cx * by - cy * bx;
    float ev = ax * cy - ay * cx;
    float ew = bx * ay - by * ax;
    if (eu == 0.f || ev == 0.f || ew == 0.f) {
        eu = edge_in_double(cx, by, cy, bx);
        ev = edge_in_double(ax, cy, ay, cx);
        ew = edge_in_double(bx, ay, by, ax);
    }
    if ((eu < 0.f || ev < 0.f || ew < 0.f) && (eu > 0.f || ev > 0.f || ew > 0.f)) return false;
    const float det = eu + ev + ew;
    if (!det_in_range(det)) return false;
    const float az = r.sz * a_kz, bz = r.sz * b_kz, cz = r.sz * c_kz;
    const float t0 = eu * az, t1 = ev * bz, t2 = ew * cz;
    const float big_t = t0 + t1 + t2;
    const float inv_det = 1.f / det;
    t = big_t * inv_det;
    u = ev * inv_det;
    v = ew * inv_det;
    if (!(std::fabs(t) < kInfinity)) return false;
    const float lateral = std::max(std::max(std::max(std::fabs(ax), std::fabs(bx)), std::fabs(cx)),
                                   std::max(std::max(std::fabs(ay), std::fabs(by)), std::fabs(cy)));
    const float depth = std::max(std::max(a_kz, b_kz), c_kz) - std::min(std::min(a_kz, b_kz), c_kz);
    if (!ill_conditioned(lateral, depth, det) && !t_underflowed(big_t, t0, t1, t2)) [[likely]] return true;
    const float xs[3] = {c9[r.kx], c9[3 + r.kx], c9[6 + r.kx]};
    const float ys[3] = {c9[r.ky], c9[3 + r.ky], c9[6 + r.ky]};
    const float zs[3] = {c9[r.kz], c9[3 + r.kz], c9[6 + r.kz]};
    return refined_t(xs, ys, zs, ox, oy, oz, r.sx, r.sy, r.sz, t, u, v);
}

#if defined(CELLRT_SSE2_TRIANGLE)
// The scalar test out of line, for the SSE2 test's rare edge functions of exactly zero and
// ill-conditioned hits: inlined, its registers would crowd the common path's.
[[gnu::noinline]] inline bool intersect_unbounded_rare(const WatertightRay& r, const Triangle& tri, float& t, float& u, float& v) {
    return intersect_unbounded_scalar(r, tri, t, u, v);
}

// The same test with the three vertices in the lanes of SSE2 registers (lane 0: v0, 1: v1, 2: v2):
// each lane runs the scalar test's operations in the same order, so every value carries the same
// bits (tests/test_watertight.cpp compares the two on random, degenerate, axis-parallel and
// edge-point rays). An edge function of exactly zero goes to the scalar test, whose double-precision
// recomputation decides it, and so does an ill-conditioned hit, whose t it takes again.
[[gnu::always_inline]] inline bool intersect_unbounded_sse(const WatertightRay& r, const Triangle& tri, float& t, float& u, float& v) {
    const float* c9 = reinterpret_cast<const float*>(&tri);
    const __m128 cz = _mm_setr_ps(c9[r.kz], c9[3 + r.kz], c9[6 + r.kz], 0.f);
    const __m128 cx = _mm_setr_ps(c9[r.kx], c9[3 + r.kx], c9[6 + r.kx], 0.f);
    const __m128 cy = _mm_setr_ps(c9[r.ky], c9[3 + r.ky], c9[6 + r.ky], 0.f);
    const __m128 dz = _mm_sub_ps(cz, _mm_set1_ps(r.org[r.kz]));  // a_kz, b_kz, c_kz
    const __m128 x = _mm_sub_ps(_mm_sub_ps(cx, _mm_set1_ps(r.org[r.kx])), _mm_mul_ps(_mm_set1_ps(r.sx), dz));
    const __m128 y = _mm_sub_ps(_mm_sub_ps(cy, _mm_set1_ps(r.org[r.ky])), _mm_mul_ps(_mm_set1_ps(r.sy), dz));
    // (eu, ev, ew) = (cx by - cy bx, ax cy - ay cx, bx ay - by ax): lanes (c, a, b) times (b, c, a).
    const __m128 x1 = _mm_shuffle_ps(x, x, _MM_SHUFFLE(3, 0, 2, 1)), x2 = _mm_shuffle_ps(x, x, _MM_SHUFFLE(3, 1, 0, 2));
    const __m128 y1 = _mm_shuffle_ps(y, y, _MM_SHUFFLE(3, 0, 2, 1)), y2 = _mm_shuffle_ps(y, y, _MM_SHUFFLE(3, 1, 0, 2));
    const __m128 e = _mm_sub_ps(_mm_mul_ps(x2, y1), _mm_mul_ps(y2, x1));
    const __m128 zero = _mm_setzero_ps();
    if ((_mm_movemask_ps(_mm_cmpeq_ps(e, zero)) & 7) != 0) return intersect_unbounded_rare(r, tri, t, u, v);
    if ((_mm_movemask_ps(_mm_cmplt_ps(e, zero)) & 7) != 0 && (_mm_movemask_ps(_mm_cmpgt_ps(e, zero)) & 7) != 0)
        return false;
    const float eu = _mm_cvtss_f32(e), ev = _mm_cvtss_f32(_mm_shuffle_ps(e, e, 1)), ew = _mm_cvtss_f32(_mm_movehl_ps(e, e));
    // Three non-zero edges of one sign: their sum is not zero (the scalar test's det == 0 case
    // needs a zero edge, which went to it above), but it may leave the normal range.
    const float det = eu + ev + ew;
    if (!det_in_range(det)) return false;
    const __m128 p = _mm_mul_ps(e, _mm_mul_ps(_mm_set1_ps(r.sz), dz));  // eu az, ev bz, ew cz
    const float big_t = (_mm_cvtss_f32(p) + _mm_cvtss_f32(_mm_shuffle_ps(p, p, 1))) + _mm_cvtss_f32(_mm_movehl_ps(p, p));
    const float inv_det = 1.f / det;
    t = big_t * inv_det;
    u = ev * inv_det;
    v = ew * inv_det;
    if (!(std::fabs(t) < kInfinity)) return false;
    const __m128 sign = _mm_set1_ps(-0.f);
    const __m128 xy = _mm_max_ps(_mm_andnot_ps(sign, x), _mm_andnot_ps(sign, y));
    const float lateral = std::max(std::max(_mm_cvtss_f32(xy), _mm_cvtss_f32(_mm_shuffle_ps(xy, xy, 1))),
                                   _mm_cvtss_f32(_mm_movehl_ps(xy, xy)));
    const float a_kz = _mm_cvtss_f32(dz), b_kz = _mm_cvtss_f32(_mm_shuffle_ps(dz, dz, 1)), c_kz = _mm_cvtss_f32(_mm_movehl_ps(dz, dz));
    const float depth = std::max(std::max(a_kz, b_kz), c_kz) - std::min(std::min(a_kz, b_kz), c_kz);
    if (ill_conditioned(lateral, depth, det) ||
        t_underflowed(big_t, _mm_cvtss_f32(p), _mm_cvtss_f32(_mm_shuffle_ps(p, p, 1)), _mm_cvtss_f32(_mm_movehl_ps(p, p))))
        [[unlikely]] return intersect_unbounded_rare(r, tri, t, u, v);
    return true;
}
#endif

// The test every path calls: SSE2's on x86-64 hosts, the scalar one elsewhere and on devices.
[[gnu::always_inline]] CELLRT_HD inline bool intersect_unbounded(const WatertightRay& r, const Triangle& tri, float& t, float& u, float& v) {
#if defined(CELLRT_SSE2_TRIANGLE)
    return intersect_unbounded_sse(r, tri, t, u, v);
#else
    return intersect_unbounded_scalar(r, tri, t, u, v);
#endif
}

// Closest-hit step: updates `best` when the triangle is hit at ray.tnear <= t <= best.t and is
// preferred by the hit rule (ray.hpp). Returns whether `best` changed. `prim` is the triangle's index,
// or a callable returning it (read only when the hit is a candidate, for structures that keep it apart).
template <class Prim>
[[gnu::always_inline]] CELLRT_HD inline bool intersect_closest(const WatertightRay& r, float tnear, const Triangle& tri, Prim&& prim, Hit& best) {
    float t, u, v;
    if (!intersect_unbounded(r, tri, t, u, v)) return false;
    if (!(t >= tnear) || !(t <= best.t)) return false;
    std::uint32_t index;
    if constexpr (std::is_invocable_v<Prim>) index = prim();
    else index = prim;
    if (!closer(t, index, best)) return false;
    best = Hit{t, index, u, v};
    return true;
}

// Any-hit step: whether the triangle is hit at tnear <= t <= tfar.
[[gnu::always_inline]] CELLRT_HD inline bool intersect_any(const WatertightRay& r, float tnear, float tfar, const Triangle& tri) {
    float t, u, v;
    return intersect_unbounded(r, tri, t, u, v) && t >= tnear && t <= tfar;
}

}  // namespace cellrt
