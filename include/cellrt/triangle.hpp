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

// Core of the test: on success writes t = T/det and the barycentrics, without any range check.
// Returns false when the ray misses the triangle's plane region or the triangle is degenerate
// (det == 0: zero area, or seen edge-on), and where the float arithmetic left its range: det not a
// normal float (the edge functions' products over- or underflowed: vertices some 1e19 or 1e-19 from
// the ray in the sheared space), or t not finite (T grows as the cube of the distance, and
// overflows some 1e13 away along a unit direction). t there is 0, noise or inf, which no
// structure's interval reaches (an interval from tnear past the scene box, say, culls what brute
// force would take): docs/HIT_SEMANTICS.md, "Known limits". Always inlined, as the
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
        eu = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
        ev = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
        ew = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
    }
    if ((eu < 0.f || ev < 0.f || ew < 0.f) && (eu > 0.f || ev > 0.f || ew > 0.f)) return false;
    const float det = eu + ev + ew;
    if (!det_in_range(det)) return false;
    const float az = r.sz * a_kz, bz = r.sz * b_kz, cz = r.sz * c_kz;
    const float big_t = eu * az + ev * bz + ew * cz;
    const float inv_det = 1.f / det;
    t = big_t * inv_det;
    u = ev * inv_det;
    v = ew * inv_det;
    return std::fabs(t) < kInfinity;
}

#if defined(CELLRT_SSE2_TRIANGLE)
// The scalar test out of line, for the SSE2 test's rare edge functions of exactly zero: inlined, its
// registers would crowd the common path's.
[[gnu::noinline]] inline bool intersect_unbounded_exact_edges(const WatertightRay& r, const Triangle& tri, float& t, float& u, float& v) {
    return intersect_unbounded_scalar(r, tri, t, u, v);
}

// The same test with the three vertices in the lanes of SSE2 registers (lane 0: v0, 1: v1, 2: v2):
// each lane runs the scalar test's operations in the same order, so every value carries the same
// bits (tests/test_watertight.cpp compares the two on random, degenerate, axis-parallel and
// edge-point rays). An edge function of exactly zero goes to the scalar test, whose double-precision
// recomputation decides it.
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
    if ((_mm_movemask_ps(_mm_cmpeq_ps(e, zero)) & 7) != 0) return intersect_unbounded_exact_edges(r, tri, t, u, v);
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
    return std::fabs(t) < kInfinity;
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
