// BIH traversal kernels for single rays (Wächter & Keller 2006, section 2.3): branched, and the
// study's branchless variant (its section 4.5 applied to BIH), both the kernels the BIH shares with
// the kd-tree (kernel/stack_traversal.hpp), which visit nodes conservatively (kernel/traversal.hpp) and
// so return exactly the hits of brute force.
//
// The direction's sign on the node's axis decides which child is near: for a positive direction the
// left child is near and is left at the left clip plane, the right child is entered at the right
// clip plane; for a negative one the roles swap. So the near child's plane is clip(sign) and the far
// child's clip(sign ^ 1). A ray between the planes of a split with a gap visits neither.
#pragma once

#include "kernel/stack_traversal.hpp"
#include "bih_tree.hpp"

namespace cellrt::detail {

// The BIH's hooks for the shared stack traversals (kernel/stack_traversal.hpp): two clip planes per
// inner node, with a gap between them that a ray can pass through.
struct BihTraits {
    using Node = BihNode;
    static constexpr int kMaxDepth = kBihMaxDepth;
    static constexpr bool kGaps = true;
    static constexpr std::uint32_t kSentinel = 1;  // the empty padding leaf after the root (bih_tree.hpp)
    static constexpr bool kLeafEntriesIndexTriangles = false;
    CELLRT_HD static float plane(const BihNode& n, std::uint32_t side) { return n.clip(side); }
    template <class Memory>
    CELLRT_HD static LeafEntry leaf_entry(const Memory& mem, std::uint32_t k) {
        return {mem.triangle(k), mem.index(k)};
    }

    // A leaf is a range of the BIH's own reordered triangles; the scene's index is read only for a
    // candidate hit.
    struct Leaves {
        template <class Memory, class Query, class Counters>
        CELLRT_HD bool test(const BihNode& leaf, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
            c.leaf();
            const std::uint32_t end = leaf.first() + leaf.count();
            for (std::uint32_t k = leaf.first(); k < end; ++k) {
                c.triangle();
                if (q.test(r.watertight, mem.triangle(k), [&] { return mem.index(k); })) return true;
            }
            return false;
        }
    };
};

enum class BihTraversal { branched, branchless };

// Calls fn(kernel) with the kernel of `t`, kernel(tree, memory, ray, query, counters).
template <class Fn>
decltype(auto) with_bih_kernel(BihTraversal t, Fn&& fn) {
    if (t == BihTraversal::branched) return fn(BranchedKernel<BihTraits>{});
    return fn(BranchlessKernel<BihTraits>{});
}

}  // namespace cellrt::detail
