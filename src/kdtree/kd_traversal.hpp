// kd-tree traversal kernels for single rays: Havran's TA_rec here, and the classic stack traversal
// and the study's branchless variant through the kernels it shares with the BIH
// (kernel/stack_traversal.hpp). Each is one template over the query (closest or any hit), the memory
// policy (direct, or the local-store model's software caches) and the work counters; all three visit
// cells conservatively (traversal.hpp) and so return exactly the hits of brute force.
//
// Memory: every kernel touches an inner node's child pair (siblings share a line) as soon as it reads
// the node, and reads a node only when it goes there: the study's asynchronous access, free when
// memory is direct.
#pragma once

#if defined(__SSE2__) && !defined(__CUDA_ARCH__)
#include <emmintrin.h>
#endif

#include "kernel/stack_traversal.hpp"
#include "kd_tree.hpp"

namespace cellrt::detail {

// The last few triangles a ray tested (the "mailbox" of Amanatides & Woo 1987; Havran's thesis
// section 4.5; not the study's mailbox dispatch of src/schedule): a kd-tree references a triangle
// from every leaf it overlaps, and a ray crossing neighbouring leaves would test it again with the
// same answer. The last eight distinct triangles, as an array written round robin (devices), or on
// x86-64 hosts as a queue in two SSE2 registers, compared at once and shifted by one entry per
// insertion (no store that the next leaf's load would wait on). Both hold the same triangles, so a
// kernel tests the same ones wherever it runs (KdTree.MailboxQueueHoldsWhatTheArrayHolds).
struct RecentTrianglesArray {
    static constexpr int kSize = 8;
    std::uint32_t slot[kSize] = {~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u};
    unsigned next = 0;

    // True when `prim` was tested recently; otherwise remembers it.
    CELLRT_HD bool seen(std::uint32_t prim) {
        bool found = false;
        for (int i = 0; i < kSize; ++i) found |= slot[i] == prim;
        if (!found) slot[next++ % kSize] = prim;
        return found;
    }
};

#if defined(__SSE2__) && !defined(__CUDA_ARCH__)
struct RecentTrianglesSse {
    __m128i newer = _mm_set1_epi32(-1), older = _mm_set1_epi32(-1);  // entries 0-3 and 4-7, newest first

    bool seen(std::uint32_t prim) {
        const __m128i p = _mm_set1_epi32(static_cast<int>(prim));
        if (_mm_movemask_epi8(_mm_or_si128(_mm_cmpeq_epi32(newer, p), _mm_cmpeq_epi32(older, p))) != 0) return true;
        older = _mm_or_si128(_mm_slli_si128(older, 4), _mm_srli_si128(newer, 12));
        newer = _mm_or_si128(_mm_slli_si128(newer, 4), _mm_cvtsi32_si128(static_cast<int>(prim)));
        return false;
    }
};
using RecentTriangles = RecentTrianglesSse;
#else
using RecentTriangles = RecentTrianglesArray;
#endif

// The kd-tree's hooks for the shared stack traversals (kernel/stack_traversal.hpp): one plane per
// inner node, which ends the left child's cell and begins the right one's.
struct KdTraits {
    using Node = KdNode;
    static constexpr int kMaxDepth = kKdMaxDepth;
    static constexpr bool kGaps = false;
    static constexpr bool kLeafEntriesIndexTriangles = true;
    CELLRT_HD static float plane(const KdNode& n, std::uint32_t) { return n.split(); }
    template <class Memory>
    CELLRT_HD static LeafEntry leaf_entry(const Memory& mem, std::uint32_t k) {
        const std::uint32_t prim = mem.index(k);
        return {mem.triangle(prim), prim};
    }

    // A leaf's entries index the scene's triangles; the mailbox skips those tested in earlier leaves.
    struct Leaves {
        RecentTriangles tested;

        template <class Memory, class Query, class Counters>
        CELLRT_HD bool test(const KdNode& leaf, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
            c.leaf();
            const std::uint32_t end = leaf.first() + leaf.count();
            for (std::uint32_t k = leaf.first(); k < end; ++k) {
                const std::uint32_t prim = mem.index(k);
                if (tested.seen(prim)) continue;
                c.triangle();
                if (q.test(r.watertight, mem.triangle(prim), prim)) return true;
            }
            return false;
        }
    };
};

// Havran's TA_rec (thesis, appendix C, the "B" variant): the stack holds points on the ray, not
// intervals. Each inner node is classified by comparing the coordinates of the current entry and exit
// points with the split; only when the ray crosses the plane is its distance computed and a new
// point pushed, which links to the exit point it replaces and names the far child that starts there.
// A leaf's exit point is the next cell's entry. For robustness a point carries two positions: where
// the near child is left (t plus the margin of the plane's axis) and where the far child is entered
// (t minus it: kernel/traversal.hpp), and the
// one-sided cases require both points to lie a coordinate margin clear of the plane.
// Coordinates of a point without Vec3's zero initialisers: the stack's points are written before
// they are read, and zeroing all of them cost each ray some 300 instructions.
struct KdRecCoords {
    float c[3];
    CELLRT_HD KdRecCoords& operator=(const Vec3& v) {
        c[0] = v.x;
        c[1] = v.y;
        c[2] = v.z;
        return *this;
    }
    CELLRT_HD float operator[](int axis) const { return c[axis]; }
};

struct KdRecPoint {
    float t_exit, t_entry;  // as the exit of the near child / the entry of the far child
    KdRecCoords exit, entry;
    std::uint32_t far;      // the node that starts at this point (~0u: the ray's end)
    int prev;               // the exit point of `far`
};
static_assert(sizeof(KdRecPoint) == 40, "the local-store model budgets TA_rec's stack at 40 bytes a point");
inline constexpr int kKdRecStackSize = kKdMaxDepth + 3;

// Flattened (every call inlined) on hosts: left to GCC's budget in the registry's unit, where every
// tree's kernels are instantiated, the leaf test went in or out of line with changes to other
// kernels, 8 % of TA_rec's instructions on Sponza's camera rays (docs/INCOHERENT.md).
template <class Tree, class Query, class Memory, class Counters>
[[gnu::flatten]] CELLRT_HD bool kd_traverse_rec(const Tree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
    constexpr std::uint32_t kNone = ~0u;
    using Point = KdRecPoint;
    float tmin, tmax;
    if (!r.clip(tree.bounds, tmin, tmax)) return false;
    // An end at infinity (the ray unbounded there, and the box's plane distance overflowed: a scene
    // reaching past 1.7e38 or so) has no point: inf times a zero component is NaN, and the planes'
    // tests then chose children at random (found by audit, 2026-12-07). The largest finite t stands
    // for it: a zero component then gives the origin's coordinate, a non-zero one +-inf, which every
    // plane compares with rightly, and no hit's t, which is finite, lies beyond it. (A branch to the
    // interval traversal instead cost the CUDA kernels some 900 bytes of stack a thread, and spills.)
    tmin = finite_tnear(tmin);
    tmax = finite_tfar(tmax);
    KdTraits::Leaves leaves;
    // Coordinates of points on the ray are exact to a few ulps of the largest coordinate involved
    // (KdRecKernel sends the rays for which this is 0 * inf elsewhere).
    const float reach = r.margin * length(r.dir);
    const Vec3 o = abs(r.org);
    const float tol = reach + kMarginScale * std::max(o.x, std::max(o.y, o.z));
    Point stack[kKdRecStackSize];
    int en = 0, ex = 1;
    stack[en].t_entry = tmin;
    stack[en].entry = r.at(tmin);
    stack[ex].t_exit = tmax;
    stack[ex].exit = r.at(tmax);
    stack[ex].far = kNone;
    stack[ex].prev = -1;
    std::uint32_t index = 0;
    for (;;) {
        KdNode n = mem.node(index);
        while (!n.is_leaf()) {
            c.node();
            mem.touch_node(n.children());
            const int a = n.axis();
            const float s = n.split();
            const float p0 = stack[en].entry[a], p1 = stack[ex].exit[a];
            const bool left_ok = std::min(p0, p1) <= s + tol, right_ok = std::max(p0, p1) >= s - tol;
            if (!right_ok) {
                index = n.children();
            } else if (!left_ok) {
                index = n.children() + 1;
            } else {
                // The ray crosses (or runs along) the plane: near child first, far child from the new point.
                const float t = (s - r.org[a]) * r.inv_dir[a];
                const std::uint32_t near = n.children() + r.dir_neg[a];
                int k = ex + 1;
                if (k == en) ++k;
                Point& pt = stack[k];
                pt.t_exit = min_keep(stack[ex].t_exit, t + r.axis_margin[a]);
                pt.t_entry = max_keep(stack[en].t_entry, t - r.axis_margin[a]);
                pt.exit = r.at(pt.t_exit);
                pt.entry = r.at(pt.t_entry);
                pt.far = near ^ 1u;
                pt.prev = ex;
                ex = k;
                index = near;
            }
            n = mem.node(index);
        }
        if (leaves.test(n, mem, r, q, c)) return true;
        // Continue with the node that starts at the leaf's exit point, unless it starts past the answer.
        for (;;) {
            if (stack[ex].far == kNone) return false;
            en = ex;
            ex = stack[en].prev;
            if (!(stack[en].t_entry > q.cull_t())) break;
        }
        index = stack[en].far;
    }
}

}  // namespace cellrt::detail

namespace cellrt::detail {

// The traversals by name, as function objects, so that callers choose one per batch, not per ray.
enum class KdTraversal { rec, branched, branchless };

struct KdRecKernel {
    template <class Tree, class Memory, class Query, class Counters>
    CELLRT_HD bool operator()(const Tree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) const {
        // Where the direction's length squared under- or overflows (components below 1e-19 or above
        // 1e19), or the margin is infinite, TA_rec's coordinate tolerance, the margin times that
        // length, is 0 or inf: no bound on its points' coordinates is known. Such a ray takes the
        // interval traversal, whose tests are on t alone (checked here, so that TA_rec's own code,
        // the study's, stays as it was).
        const float reach = r.margin * length(r.dir);
        if (!(reach > 0.f && reach < kInfinity)) return traverse_branched<KdTraits>(tree, mem, r, q, c);
        return kd_traverse_rec(tree, mem, r, q, c);
    }
};

// Calls fn(kernel) with the kernel of `t`, kernel(tree, memory, ray, query, counters).
template <class Fn>
decltype(auto) with_kd_kernel(KdTraversal t, Fn&& fn) {
    switch (t) {
        case KdTraversal::rec: return fn(KdRecKernel{});
        case KdTraversal::branched: return fn(BranchedKernel<KdTraits>{});
        default: return fn(BranchlessKernel<KdTraits>{});
    }
}

}  // namespace cellrt::detail
