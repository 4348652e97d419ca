// The BIH's descriptor: what every consumer of the structure needs, in one place (the members are
// those of KdStructure, described in kdtree/kd_structure.hpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bih_traversal.hpp"
#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"
#include "kernel/named.hpp"
#include "kernel/tree_report.hpp"

namespace cellrt::detail {

// The build parameters of `config`, validated against the table; threads from config.threads.
BihBuildParams read_bih_params(const AccelConfig& config);

// The BIH keeps its own reordered copy of the triangles.
struct BihStructure {
    static constexpr double kReportTraversalCost = 15.0, kReportIntersectionCost = 20.0;
    using Traits = BihTraits;
    using Node = BihNode;
    using Traversal = BihTraversal;
    static constexpr const char* kName = "bih";
    static constexpr Named<BihTraversal> kTraversals[] = {{"branched", BihTraversal::branched},
                                                          {"branchless", BihTraversal::branchless}};

    template <class Fn>
    static decltype(auto) with_kernel(Traversal t, Fn&& fn) {
        return with_bih_kernel(t, std::forward<Fn>(fn));
    }
    static const ParamTable& param_table();
    static std::size_t stack_bytes(Traversal) { return kBranchlessStackSize<BihTraits> * sizeof(StackEntry); }

    BihStructure(std::span<const Triangle> tris, const AccelConfig& config)
        : params(read_bih_params(config)), tree(build_bih(tris, params)) {}
    const Box3& bounds() const { return tree.bounds; }
    std::span<const BihNode> nodes() const { return tree.nodes; }
    std::span<const std::uint32_t> entries() const { return tree.prims; }
    std::span<const Triangle> triangle_array() const { return tree.triangles; }
    TreeView<BihTraits> view() const {
        return {tree.nodes.data(), tree.prims.data(), tree.triangles.data(), tree.bounds};
    }
    std::size_t memory_bytes() const {
        return nodes().size_bytes() + entries().size_bytes() + triangle_array().size_bytes();
    }
    // The SAH cost in the kd-tree's default cost units whatever the build used, so that the two
    // structures' reports compare.
    TreeReport report() const {
        return tree_report(view(), {kReportTraversalCost, kReportIntersectionCost}, params.max_depth,
                           tree.triangles.size());
    }
    std::vector<std::pair<std::string, std::string>> settings() const;

    BihBuildParams params;
    BihTree tree;
};

}  // namespace cellrt::detail
