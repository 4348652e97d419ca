// The kd-tree's descriptor: what every consumer of the structure needs, in one place. The registry
// (src/accel) lists it once; the accelerator shell, the SIMD packets and the local-store model are
// templates over a descriptor, and a device copy reads the layout from its traits. A descriptor has:
//
//   kName, Traits, Node                   the kind's name; the traversal traits (kd_traversal.hpp) and node
//   Traversal, kTraversals                the single-ray traversals by name, the default first
//   with_kernel(traversal, fn)            calls fn(kernel), kernel(tree, memory, ray, query, counters)
//   param_table()                         the build parameters: name, default, range, meaning
//   S(triangles, config)                  validates config.params against the table, then builds
//   bounds(), nodes(), entries(), triangle_array(), view()
//                                         the built tree: its root cell and the three arrays its kernels
//                                         read, and the same as a TreeView for the packets
//   memory_bytes(), report(), settings()  its size, typed build report and the settings it was built with
//   stack_bytes(traversal)                the traversal stack a kernel declares (the local store holds it)
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"
#include "kd_traversal.hpp"
#include "kernel/named.hpp"
#include "kernel/tree_report.hpp"

namespace cellrt::detail {

// The build parameters of `config` (validated against the table; threads from config.threads). With
// SIMD packets (config.simd other than "off") traversal_cost defaults to kKdPacketTraversalCost.
KdBuildParams read_kd_params(const AccelConfig& config);

struct KdStructure {
    using Traits = KdTraits;
    using Node = KdNode;
    using Traversal = KdTraversal;
    static constexpr const char* kName = "kd";
    static constexpr Named<KdTraversal> kTraversals[] = {
        {"branched", KdTraversal::branched}, {"rec", KdTraversal::rec}, {"branchless", KdTraversal::branchless}};

    template <class Fn>
    static decltype(auto) with_kernel(Traversal t, Fn&& fn) {
        return with_kd_kernel(t, std::forward<Fn>(fn));
    }
    static const ParamTable& param_table();
    static std::size_t stack_bytes(Traversal t) {
        if (t == KdTraversal::rec) return kKdRecStackSize * sizeof(KdRecPoint);
        return kBranchlessStackSize<KdTraits> * sizeof(StackEntry);
    }

    // Leaves index `tris`, which must outlive the structure.
    KdStructure(std::span<const Triangle> tris, const AccelConfig& config)
        : params(read_kd_params(config)), triangles(tris), tree(build_kdtree(tris, params)) {}
    const Box3& bounds() const { return tree.bounds; }
    std::span<const KdNode> nodes() const { return tree.nodes; }
    std::span<const std::uint32_t> entries() const { return tree.indices; }
    std::span<const Triangle> triangle_array() const { return triangles; }
    TreeView<KdTraits> view() const { return {tree.nodes.data(), tree.indices.data(), triangles.data(), tree.bounds}; }
    std::size_t memory_bytes() const { return nodes().size_bytes() + entries().size_bytes(); }
    // The SAH cost in the tree's own cost units.
    TreeReport report() const {
        return tree_report(view(), {params.traversal_cost, params.intersection_cost},
                           params.depth_limit(tree.triangle_count), tree.triangle_count);
    }
    std::vector<std::pair<std::string, std::string>> settings() const;

    KdBuildParams params;
    std::span<const Triangle> triangles;
    KdTree tree;
};

}  // namespace cellrt::detail
