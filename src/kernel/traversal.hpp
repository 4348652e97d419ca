// Pieces every single-ray traversal kernel shares (kd-tree, BIH; direct memory or the local-store
// model): the prepared ray and its robustness margin, the two queries (closest hit, any hit), the work
// counters, direct memory access, and the batch loop that turns the accelerator boundary's calls into
// kernel calls with one dispatch per batch.
//
// Robustness. A structure only decides which triangles to test; hits are accepted by the hit rule
// alone (ray.hpp), never by a cell's interval. Every decision that could skip a triangle is made
// conservative by a margin `m` in ray parameter t: a cell is visited when the ray passes within m of
// it, and a cell is skipped after a hit only when it starts more than m beyond the best t. m bounds
// the rounding error of both a plane distance and the watertight test's t for points inside the scene
// box: it is a fixed fraction of the largest distance from the origin to the box, in units of t.
// A plane of axis a is widened by at least m/16 · |d|/|d_a| as well (axis_margins): 2^-20 of the
// reach in space, across the plane. An ill-conditioned hit's t (triangle.hpp, refined_t) is the
// depth of a point within rounding of the ray in space, which on a ray nearly parallel to the plane
// can lie far in t from where the ray crosses it: a triangle in an axis plane, in a box or cell of no
// thickness there, was culled by a margin in t alone (found by audit, 2026-12-07:
// Structures/GrazingAxisPlanes).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>

#include "cellrt/accelerator.hpp"
#include "cellrt/box.hpp"
#include "cellrt/host_device.hpp"
#include "cellrt/ray.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt::detail {

// Relative size of the margin: 2^-16 of the scene's extent as seen from the origin. The errors it
// covers are a few units in the last place (2^-24) of that extent.
inline constexpr float kMarginScale = 1.f / 65536.f;

// min/max that keep the first operand when the second is NaN (a ray lying exactly in a plane gives
// 0 * inf = NaN for the plane's distance, and then the plane must not cut the interval).
CELLRT_HD inline float min_keep(float kept, float x) { return x < kept ? x : kept; }
CELLRT_HD inline float max_keep(float kept, float x) { return x > kept ? x : kept; }

// The least margin, an absolute error of t that the relative margin does not cover. Where the
// watertight test's T is subnormal (triangles near 1e-13 and below from the origin along a unit
// direction; T grows as their distance cubed), it is exact only to about 2^-149, and t = T / det,
// det at least 2^-126 (det_in_range), to about 2^-21.5; this keeps four times that. It only acts
// where the whole scene lies within t < 2^-4 of the origin: for ordinary scenes and directions
// the relative margin is larger (a 1e-17 scene along unit directions had garbage t of 0 that
// brute force ranked first and the structures culled). Such hits now take t in double precision
// (triangle.hpp, t_underflowed); the floor still covers that t's rounding to float.
inline constexpr float kMarginFloor = 0x1p-20f;

// The margin in t: kMarginScale times the largest distance from the origin to the scene box
// (`reach`, per axis), over the direction's length, at least kMarginFloor and at most FLT_MAX.
// Taken directly, the lengths' squares overflow where components pass about 1e19 and underflow to
// 0 below about 1e-23 (scenes of such coordinates, directions of such lengths): inf / inf or 0 / 0
// gave a NaN margin that culled every cell (a glTF scene at 8.4e18, found by fuzz_gltf), and
// finite / inf a margin of 0. A result that is not positive and finite is therefore taken again
// with both vectors divided by their largest component, out of line and with its arguments by
// value, so that ordinary rays pay only the test (1 % of a kd-tree's camera ray's instructions on
// the bunny, callgrind). A square that underflows into the subnormals keeps a few bits, enough
// for a margin, whose slack over the errors it covers is 2^8.
CELLRT_HD inline float at_least_floor(float margin) { return margin < kMarginFloor ? kMarginFloor : margin; }
[[gnu::noinline]] CELLRT_NOINLINE CELLRT_HD inline float traversal_margin_rescaled(Vec3 reach, Vec3 dir) {
    const Vec3 d = abs(dir);
    const float rm = std::max(reach.x, std::max(reach.y, reach.z)), dm = std::max(d.x, std::max(d.y, d.z));
    // No bound, but a finite one: a margin of inf made inf - inf = NaN of an entry distance that
    // overflowed, and the BVH's box test does not meet a NaN entry.
    if (rm == kInfinity || dm == 0.f) return kLargestFloat;  // the box's distance overflowed, or no direction
    if (rm == 0.f) return kMarginFloor;                      // the box is one point, the origin
    // Lengths of vectors with a largest component of 1: within [1, sqrt 3], exact to a few ulps.
    const float m = kMarginScale * (length(reach / rm) / length(d / dm)) * (rm / dm);
    return m < kLargestFloat ? at_least_floor(m) : kLargestFloat;
}
// Whether a margin taken directly can stand: positive and finite (NaN fails).
CELLRT_HD inline bool direct_margin_holds(float m) { return m > 0.f && m < kInfinity; }
[[gnu::always_inline]] CELLRT_HD inline float traversal_margin(const Vec3& reach, const Vec3& dir) {
    const float m = kMarginScale * length(reach) / length(dir);
    if (direct_margin_holds(m)) [[likely]] return at_least_floor(m);
    return traversal_margin_rescaled(reach, dir);
}

// The margins of the three axes' planes, in t, from the margin in t, the direction's largest
// component |d|max and the reciprocal direction: the larger of the margin and the margin times
// (√3/16 · |d|max · |1/d_a|), which is at least a sixteenth of the margin times |d|, the margin as a
// length along the ray, over |d_a|: a plane is widened in space across it by 2^-20 of the
// scene's reach, sixteen times the rounding of a point within rounding of the ray (and of a
// refined hit's, some 2^-30 of it where measured). A sixteenth: the whole margin across the planes
// cost camera rays 1.4 % more leaves and 2.4 % more triangles (the bunny's kd-tree), rays nearly
// parallel to the planes running along them within the margin for long. At most FLT_MAX (a zero
// component's, whose plane distances are infinite or NaN, which no finite margin moves). The SIMD
// set-up (simd/ray_lanes.inl) takes the same operations in the same order.
inline constexpr float kAcrossScale = 0x1.bb67b0p-4f;  // √3/16 rounded up
template <class Inverse>
[[gnu::always_inline]] CELLRT_HD inline Vec3 axis_margins(float margin, float dir_max, const Inverse& inv) {
    // The factors first, apart from the margin, which comes last on the set-up's longest chain.
    const float spread = kAcrossScale * dir_max;
    Vec3 m;
    for (int a = 0; a < 3; ++a) {
        const float x = margin * (spread * std::fabs(inv[a]));
        m[a] = x < kLargestFloat ? (x > margin ? x : margin) : kLargestFloat;
    }
    return m;
}

struct TraversalRay {
    Vec3 org, dir, inv_dir;
    std::uint32_t dir_neg[3];  // 1 where the direction's sign bit is set (-0 included): the near child index
    float tnear, tfar;
    float margin;       // in t: of the ray's bounds and the queries' cull distance
    Vec3 axis_margin;   // of each axis' planes (axis_margins)
    WatertightRay watertight;

    // Always inlined, with clip() and the triangle test (triangle.hpp): see intersect_unbounded.
    [[gnu::always_inline]] CELLRT_HD TraversalRay(const Ray& r, const Box3& scene_box)
        : org(r.org), dir(traced_direction(r)), tnear(r.tnear), tfar(r.tfar), watertight(WatertightRay::of_traced(org, dir)) {
        for (int a = 0; a < 3; ++a) {
            inv_dir[a] = 1.f / dir[a];
            dir_neg[a] = std::signbit(dir[a]) ? 1u : 0u;
        }
        margin = traversal_margin(max(abs(scene_box.lo - org), abs(scene_box.hi - org)), dir);
        const Vec3 d = abs(dir);  // finite (a valid ray's): max, not fmax, which is a call
        axis_margin = axis_margins(margin, std::max(d.x, std::max(d.y, d.z)), inv_dir);
    }

    CELLRT_HD Vec3 at(float t) const { return org + dir * t; }

    // The direction's sign bits (x, y, z in bits 0-2): the octant. A kernel keeps them in a register
    // and picks the near child by a shift, `(octant >> axis) & 1`, rather than loading dir_neg[axis]:
    // the pick lies on the chain from one node's load to the next, and a load there costs its latency
    // on every step (about 10 % of a kd-tree's camera ray on Zen 4: docs/INCOHERENT.md, seventeenth round).
    CELLRT_HD std::uint32_t octant() const { return dir_neg[0] | dir_neg[1] << 1 | dir_neg[2] << 2; }

    // The ray's interval [tnear, tfar] clipped to `box`, widened by the margin and each axis' planes
    // by theirs. False when empty.
    // A slab the ray lies in exactly (origin on its face, zero direction on its axis) gives NaN and
    // does not cut the interval.
    [[gnu::always_inline]] CELLRT_HD bool clip(const Box3& box, float& tmin, float& tmax) const {
        tmin = tnear - margin;
        tmax = tfar + margin;
        for (int a = 0; a < 3; ++a) {
            const float t0 = (box.lo[a] - org[a]) * inv_dir[a];
            const float t1 = (box.hi[a] - org[a]) * inv_dir[a];
            const float enter = dir_neg[a] ? t1 : t0, leave = dir_neg[a] ? t0 : t1;
            tmin = max_keep(tmin, enter - axis_margin[a]);
            tmax = min_keep(tmax, leave + axis_margin[a]);
        }
        return tmin <= tmax;
    }
};

// Work counters: the kernels call these on every node, leaf and triangle; NoCounters compiles them away.
struct NoCounters {
    CELLRT_HD void node() {}
    CELLRT_HD void leaf() {}
    CELLRT_HD void triangle() {}
};

struct WorkCounters {
    TraversalCounters& sum;
    void node() { ++sum.nodes; }
    void leaf() { ++sum.leaves; }
    void triangle() { ++sum.triangles; }
};

// A query's bounds within the finite floats, as the SIMD set-up clamps a ray's (simd/ray_lanes.inl):
// a hit's t is finite (triangle.hpp), and the BVH's leaf lanes leave that to the bounds, t >= tnear
// and t <= tfar (or best.t), rather than testing each lane's t. Only tnear = -inf and tfar = +inf
// move (a valid ray has tnear below +inf and tnear <= tfar: ray.hpp). Written as maxss and minss
// take them, one instruction each (as `x > b ? b : x` they compiled to a compare and a blend); a
// NaN, an invalid ray's, becomes the bound, where the lanes keep it.
CELLRT_HD inline float finite_tnear(float t) { return t > -kLargestFloat ? t : -kLargestFloat; }
CELLRT_HD inline float finite_tfar(float t) { return t < kLargestFloat ? t : kLargestFloat; }

// Closest hit under the hit rule. Cells starting after best.t + margin cannot hold the answer.
struct ClosestHit {
    static constexpr bool kAnyHit = false;
    Hit best;
    float tnear;
    float margin;

    CELLRT_HD explicit ClosestHit(const TraversalRay& r)
        : ClosestHit(finite_tnear(r.tnear), finite_tfar(r.tfar), r.margin) {}
    // From the ray's interval and margin, as a SIMD set-up keeps them in lanes: the bounds finite
    // (finite_tnear, finite_tfar), which the caller ensures. Clamping them here again cost the BVH's
    // packets and paired walks 0.5 to 1.2 % of their instructions (docs/INCOHERENT.md, eighteenth
    // round); Structures/UnboundedBehind fails on any path whose bounds are not finite.
    CELLRT_HD ClosestHit(float t_near, float t_far, float m) : best{t_far, kNoHit, 0.f, 0.f}, tnear(t_near), margin(m) {}

    CELLRT_HD float cull_t() const { return best.t + margin; }
    // Tests one triangle; `prim` gives its index in the scene (read only for a candidate). Returns
    // false: a closest-hit query never ends early.
    template <class Prim>
    CELLRT_HD bool test(const WatertightRay& r, const Triangle& tri, Prim&& prim) {
        intersect_closest(r, tnear, tri, prim, best);
        return false;
    }
    CELLRT_HD Hit result() const { return best.is_hit() ? best : Hit{}; }
};

// Any hit: the first triangle with tnear <= t <= tfar ends the query.
struct AnyHit {
    static constexpr bool kAnyHit = true;
    float tnear, tfar;
    float cull;

    CELLRT_HD explicit AnyHit(const TraversalRay& r) : AnyHit(finite_tnear(r.tnear), finite_tfar(r.tfar), r.margin) {}
    // From finite bounds, as ClosestHit's.
    CELLRT_HD AnyHit(float t_near, float t_far, float margin) : tnear(t_near), tfar(t_far), cull(t_far + margin) {}

    CELLRT_HD float cull_t() const { return cull; }
    template <class Prim>
    CELLRT_HD bool test(const WatertightRay& r, const Triangle& tri, Prim&&) {
        return intersect_any(r, tnear, tfar, tri);
    }
};

// A cell waiting on the stack of the stack-based traversals.
struct StackEntry {
    std::uint32_t node;
    float tmin, tmax;
};
static_assert(sizeof(StackEntry) == 12, "a stack entry is a node index and an interval");

// Pops the next stacked cell that can still hold the answer, skipping those that start past the
// query's cull distance; false when no entry above `bottom` is left. `sp` ends on the popped slot.
template <class Query>
CELLRT_HD bool pop_live(const StackEntry* stack, int& sp, int bottom, const Query& q, std::uint32_t& node, float& tmin,
              float& tmax) {
    do {
        if (sp == bottom) return false;
        --sp;
    } while (stack[sp].tmin > q.cull_t());
    node = stack[sp].node;
    tmin = stack[sp].tmin;
    tmax = stack[sp].tmax;
    return true;
}

// Direct memory access: the kernels read nodes, leaf indices and triangles through a memory policy so
// that the local-store model can run the very same kernels. References returned by a policy are valid
// until its next access; kernels copy nodes. touch_node() announces a node that will be read later
// (the study's asynchronous access); directly it is a no-op.
template <class Node>
struct DirectMemory {
    const Node* nodes;
    const std::uint32_t* indices;
    const Triangle* triangles;

    CELLRT_HD const Node& node(std::uint32_t i) const { return nodes[i]; }
    CELLRT_HD void touch_node(std::uint32_t) const {}
    CELLRT_HD std::uint32_t index(std::uint32_t i) const { return indices[i]; }
    CELLRT_HD const Triangle& triangle(std::uint32_t i) const { return triangles[i]; }
};

// A triangle of a leaf and its index in the scene: what the traits' leaf_entry() returns.
struct LeafEntry {
    const Triangle& triangle;
    std::uint32_t prim;
};

// A built tree as its kernels see it: the node array, the leaves' entries, the triangles the entries
// lead to and the root cell. Every consumer that is not a single-ray kernel over one structure's own
// types (the SIMD packets, a device copy) reads a tree through this view and the tree's traits.
template <class Traits>
struct TreeView {
    using Node = typename Traits::Node;
    const Node* nodes;
    const std::uint32_t* entries;
    const Triangle* triangles;
    Box3 bounds;

    CELLRT_HD DirectMemory<Node> memory() const { return {nodes, entries, triangles}; }
};

// Runs `fn(counters)` with WorkCounters adding to `*sum`, or with NoCounters when `sum` is null: the
// one branch on counting, per batch.
template <class Fn>
void with_counters(TraversalCounters* sum, std::size_t rays, Fn&& fn) {
    if (sum) {
        WorkCounters count{*sum};
        fn(count);
        sum->rays += rays;
    } else {
        NoCounters count;
        fn(count);
    }
}

// One ray's query, `kernel(ray, query, counters)`: what the batch loops below run for each ray on the
// host and what each thread of the CUDA backend runs on the device (src/cuda/). An invalid ray
// (ray.hpp) hits nothing.
template <class Kernel, class Counters>
CELLRT_HD Hit closest_hit(const Box3& scene_box, const Ray& ray, Counters& count, Kernel&& kernel) {
    if (!is_valid(ray)) return Hit{};
    const TraversalRay r(ray, scene_box);
    ClosestHit q(r);
    kernel(r, q, count);
    return q.result();
}

template <class Kernel, class Counters>
CELLRT_HD bool any_hit(const Box3& scene_box, const Ray& ray, Counters& count, Kernel&& kernel) {
    if (!is_valid(ray)) return false;
    const TraversalRay r(ray, scene_box);
    AnyHit q(r);
    return kernel(r, q, count);
}

// The batch loops behind Accelerator::intersect/occluded.
template <class Kernel>
void closest_hits(const Box3& scene_box, std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters,
                  Kernel&& kernel) {
    with_counters(counters, rays.size(), [&](auto& count) {
        for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = closest_hit(scene_box, rays[i], count, kernel);
    });
}

template <class Kernel>
void any_hits(const Box3& scene_box, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
              TraversalCounters* counters, Kernel&& kernel) {
    with_counters(counters, rays.size(), [&](auto& count) {
        for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = any_hit(scene_box, rays[i], count, kernel) ? 1 : 0;
    });
}

}  // namespace cellrt::detail
