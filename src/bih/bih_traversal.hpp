// BIH traversal kernels for single rays (Wächter & Keller 2006, section 2.3): branched, and the
// study's branchless variant (its section 4.5 applied to BIH). Each is one template over the query,
// the memory policy and the work counters, like the kd-tree's (kd_traversal.hpp), and visits nodes
// conservatively (accel/traversal.hpp), so both return exactly the hits of brute force.
//
// The direction's sign on the node's axis decides which child is near: for a positive direction the
// left child is near and is left at the left clip plane, the right child is entered at the right
// clip plane; for a negative one the roles swap. So the near child's plane is clip(sign) and the far
// child's clip(sign ^ 1). A ray between the planes of a split with a gap visits neither.
#pragma once

#include "accel/traversal.hpp"
#include "bih_tree.hpp"

namespace cellrt::detail {

template <class Query, class Memory, class Counters>
bool bih_leaf(const BihNode& leaf, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
    c.leaf();
    const std::uint32_t end = leaf.first() + leaf.count();
    for (std::uint32_t k = leaf.first(); k < end; ++k) {
        c.triangle();
        if (q.test(r.watertight, mem.triangle(k), [&] { return mem.index(k); })) return true;
    }
    return false;
}

// `_from` traverses the subtree of node `index` for the ray's interval [tmin, tmax] in that cell (the
// SIMD packets hand a lane over to it when the lane is the last one left in a subtree).
template <class Query, class Memory, class Counters>
bool bih_traverse_branched_from(Memory& mem, const TraversalRay& r, Query& q, Counters& c, std::uint32_t index,
                                float tmin, float tmax) {
    StackEntry stack[kBihMaxDepth + 1];
    int sp = 0;
    for (;;) {
        BihNode n = mem.node(index);
        bool reached_leaf = true;
        while (!n.is_leaf()) {
            c.node();
            mem.touch_node(n.children());
            const int a = n.axis();
            const std::uint32_t s = r.dir_neg[a];
            const float t_near = (n.clip(s) - r.org[a]) * r.inv_dir[a];       // where the near child ends
            const float t_far = (n.clip(s ^ 1u) - r.org[a]) * r.inv_dir[a];   // where the far child begins
            const bool near_ok = !(tmin > t_near + r.margin), far_ok = !(t_far - r.margin > tmax);
            if (near_ok) {
                if (far_ok) stack[sp++] = {n.children() + (s ^ 1u), max_keep(tmin, t_far - r.margin), tmax};
                tmax = min_keep(tmax, t_near + r.margin);
                index = n.children() + s;
            } else if (far_ok) {
                tmin = max_keep(tmin, t_far - r.margin);
                index = n.children() + (s ^ 1u);
            } else {
                reached_leaf = false;  // the ray passes between the two planes
                break;
            }
            n = mem.node(index);
        }
        if (reached_leaf && bih_leaf(n, mem, r, q, c)) return true;
        if (!pop_live(stack, sp, 0, q, index, tmin, tmax)) return false;
    }
}

template <class Query, class Memory, class Counters>
bool bih_traverse_branched(const BihTree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
    float tmin, tmax;
    return r.clip(tree.bounds, tmin, tmax) && bih_traverse_branched_from(mem, r, q, c, 0, tmin, tmax);
}

// Both children's entries are written, far first, and the stack pointer moves by the two comparison
// results, then the top is popped; a ray in the gap pops the entry below. The bottom of the stack is
// a sentinel naming node 1, the empty padding leaf, which ends the traversal.
template <class Query, class Memory, class Counters>
bool bih_traverse_branchless(const BihTree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
    constexpr std::uint32_t kSentinel = 1;
    float tmin, tmax;
    if (!r.clip(tree.bounds, tmin, tmax)) return false;
    StackEntry stack[kBihMaxDepth + 3];
    stack[0] = {kSentinel, tmin, tmax};
    int sp = 1;
    std::uint32_t index = 0;
    for (;;) {
        BihNode n = mem.node(index);
        while (!n.is_leaf()) {
            c.node();
            mem.touch_node(n.children());
            const int a = n.axis();
            const std::uint32_t s = r.dir_neg[a];
            const float t_near = (n.clip(s) - r.org[a]) * r.inv_dir[a];
            const float t_far = (n.clip(s ^ 1u) - r.org[a]) * r.inv_dir[a];
            const bool near_ok = !(tmin > t_near + r.margin), far_ok = !(t_far - r.margin > tmax);
            stack[sp] = {n.children() + (s ^ 1u), max_keep(tmin, t_far - r.margin), tmax};
            sp += far_ok;
            stack[sp] = {n.children() + s, tmin, min_keep(tmax, t_near + r.margin)};
            sp += near_ok;
            --sp;
            index = stack[sp].node;
            tmin = stack[sp].tmin;
            tmax = stack[sp].tmax;
            n = mem.node(index);
        }
        if (index == kSentinel) return false;
        if (bih_leaf(n, mem, r, q, c)) return true;
        if (!pop_live(stack, sp, 1, q, index, tmin, tmax)) return false;  // entry 0 is the sentinel
    }
}

enum class BihTraversal { branched, branchless };

template <class Fn>
decltype(auto) with_bih_kernel(BihTraversal t, Fn&& fn) {
    auto branched = [](const BihTree& tree, auto& mem, const TraversalRay& r, auto& q, auto& c) {
        return bih_traverse_branched(tree, mem, r, q, c);
    };
    auto branchless = [](const BihTree& tree, auto& mem, const TraversalRay& r, auto& q, auto& c) {
        return bih_traverse_branchless(tree, mem, r, q, c);
    };
    if (t == BihTraversal::branched) return fn(branched);
    return fn(branchless);
}

}  // namespace cellrt::detail
