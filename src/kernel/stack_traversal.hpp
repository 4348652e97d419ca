// The stack traversals of a binary hierarchy of cells split on one axis, shared by the kd-tree and
// the BIH: the classic branched one (pbrt's, Wald's) and the study's branchless variant (its section
// 4.5, after Havran 2007). A kd-tree node is a BIH node whose two planes coincide: in both, the left
// child's cell ends at one plane and the right child's begins at another (Wächter & Keller 2006,
// section 2.3), and the direction's sign on the node's axis decides which child is near. So one
// kernel serves both, templated on the structure's traversal traits (`Traits`), the query (closest or any hit),
// the memory policy (direct, or the local-store model's software caches) and the work counters.
//
// Traits provides:
//   Node                              is_leaf(), axis(), children() (an adjacent pair, left first)
//   kMaxDepth                         the deepest inner node's depth
//   kGaps                             whether a ray can pass between the two planes and need neither child
//   kSentinel                         (with gaps) an empty leaf that ends the branchless traversal
//   plane(node, side)                 side 0: where the left child ends; 1: where the right child begins
//   Leaves                            per-ray state with test(leaf, mem, ray, query, counters): true when
//                                     an any-hit query is answered
//   kLeafEntriesIndexTriangles        true: a leaf's entries index the scene's triangles (the kd-tree);
//                                     false: entry k is the structure's own triangle k, and the entry its
//                                     scene index (the BIH)
//   leaf_entry(mem, k)                leaf entry k as {triangle, scene index}, for kernels that need both
//
// Both kernels visit cells conservatively (traversal.hpp) and so return exactly the hits of brute
// force. Memory: a kernel touches an inner node's child pair (siblings share a line) as soon as it
// reads the node, and reads a node only when it goes there: the study's asynchronous access, free
// when memory is direct.
#pragma once

#include "kernel/traversal.hpp"

namespace cellrt::detail {

// The stacks the kernels declare, in entries (the local-store model budgets them): the branched kernel
// pushes at most one far child per level; the branchless one writes one entry past its top and, with
// gaps, keeps a sentinel at the bottom.
template <class Traits>
inline constexpr int kBranchedStackSize = Traits::kMaxDepth + 1;
template <class Traits>
inline constexpr int kBranchlessStackSize = Traits::kMaxDepth + 2 + (Traits::kGaps ? 1 : 0);

// `_from` traverses the subtree of node `index` for the ray's interval [tmin, tmax] in that cell (the
// SIMD packets hand a lane over to it when the lane is the last one left in a subtree). The near child
// is visited first; the far one is pushed when the ray reaches it too.
template <class Traits, class Query, class Memory, class Counters>
CELLRT_HD bool traverse_branched_from(Memory& mem, const TraversalRay& r, Query& q, Counters& c, std::uint32_t index,
                            float tmin, float tmax) {
    typename Traits::Leaves leaves;
    StackEntry stack[kBranchedStackSize<Traits>];
    int sp = 0;
    const std::uint32_t octant = r.octant();
    for (;;) {
        typename Traits::Node n = mem.node(index);
        bool reached_leaf = true;
        while (!n.is_leaf()) {
            c.node();
            mem.touch_node(n.children());
            const int a = n.axis();
            const std::uint32_t s = (octant >> a) & 1u;
            const float t_near = (Traits::plane(n, s) - r.org[a]) * r.inv_dir[a];      // where the near child ends
            const float t_far = (Traits::plane(n, s ^ 1u) - r.org[a]) * r.inv_dir[a];  // where the far child begins
            const float m = r.axis_margin[a];
            // A NaN distance (the ray lies in the plane) passes both tests: both children are visited.
            const bool near_ok = !(tmin > t_near + m), far_ok = !(t_far - m > tmax);
            if (near_ok) {
                if (far_ok) stack[sp++] = {n.children() + (s ^ 1u), max_keep(tmin, t_far - m), tmax};
                tmax = min_keep(tmax, t_near + m);
                index = n.children() + s;
            } else if (!Traits::kGaps || far_ok) {  // one plane: a ray not before it is after it
                tmin = max_keep(tmin, t_far - m);
                index = n.children() + (s ^ 1u);
            } else {
                reached_leaf = false;  // the ray passes between the two planes
                break;
            }
            n = mem.node(index);
        }
        if (reached_leaf && leaves.test(n, mem, r, q, c)) return true;
        if (!pop_live(stack, sp, 0, q, index, tmin, tmax)) return false;
    }
}

template <class Traits, class Tree, class Query, class Memory, class Counters>
CELLRT_HD bool traverse_branched(const Tree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
    float tmin, tmax;
    return r.clip(tree.bounds, tmin, tmax) && traverse_branched_from<Traits>(mem, r, q, c, 0, tmin, tmax);
}

// Branchless: at an inner node both children's entries are written, far first, and the stack pointer
// moves by the two comparison results; the next node is then popped from the top. The only branch left
// in the inner loop is the loop's own. With one plane a ray always needs a child; with two it may need
// neither and pops the entry below, so the stack's bottom is a sentinel entry naming an empty leaf,
// which ends the traversal.
template <class Traits, class Tree, class Query, class Memory, class Counters>
CELLRT_HD bool traverse_branchless(const Tree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
    float tmin, tmax;
    if (!r.clip(tree.bounds, tmin, tmax)) return false;
    typename Traits::Leaves leaves;
    StackEntry stack[kBranchlessStackSize<Traits>];
    const std::uint32_t octant = r.octant();
    int bottom = 0;
    if constexpr (Traits::kGaps) stack[bottom++] = {Traits::kSentinel, tmin, tmax};
    int sp = bottom;
    std::uint32_t index = 0;
    for (;;) {
        typename Traits::Node n = mem.node(index);
        while (!n.is_leaf()) {
            c.node();
            mem.touch_node(n.children());
            const int a = n.axis();
            const std::uint32_t s = (octant >> a) & 1u;
            const float t_near = (Traits::plane(n, s) - r.org[a]) * r.inv_dir[a];
            const float t_far = (Traits::plane(n, s ^ 1u) - r.org[a]) * r.inv_dir[a];
            const float m = r.axis_margin[a];
            const bool near_ok = !(tmin > t_near + m), far_ok = !(t_far - m > tmax);
            stack[sp] = {n.children() + (s ^ 1u), max_keep(tmin, t_far - m), tmax};
            sp += far_ok;
            stack[sp] = {n.children() + s, tmin, min_keep(tmax, t_near + m)};
            sp += near_ok;
            --sp;
            index = stack[sp].node;
            tmin = stack[sp].tmin;
            tmax = stack[sp].tmax;
            n = mem.node(index);
        }
        if constexpr (Traits::kGaps) {
            if (index == Traits::kSentinel) return false;
        }
        if (leaves.test(n, mem, r, q, c)) return true;
        if (!pop_live(stack, sp, bottom, q, index, tmin, tmax)) return false;
    }
}

// The two kernels as function objects, kernel(tree, memory, ray, query, counters): what a descriptor's
// with_kernel() hands its caller, so that the host and a device (src/cuda/) instantiate the same ones.
template <class Traits>
struct BranchedKernel {
    template <class Tree, class Memory, class Query, class Counters>
    CELLRT_HD bool operator()(const Tree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) const {
        return traverse_branched<Traits>(tree, mem, r, q, c);
    }
};

template <class Traits>
struct BranchlessKernel {
    template <class Tree, class Memory, class Query, class Counters>
    CELLRT_HD bool operator()(const Tree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) const {
        return traverse_branchless<Traits>(tree, mem, r, q, c);
    }
};

}  // namespace cellrt::detail
