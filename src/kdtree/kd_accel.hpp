// The kd-tree behind the accelerator boundary (`--accel kd`).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cellrt/accel.hpp"
#include "kd_traversal.hpp"

namespace cellrt::detail {

struct PacketKernels;

// `-P` build parameters of `config`, validated (docs/KDTREE.md); throws cellrt::Error naming a bad one.
KdBuildParams read_kd_params(const AccelConfig& config);
// The single-ray traversals by name, the default first, and the one a name selects.
const std::vector<std::string>& kd_traversal_names();
KdTraversal kd_traversal(const std::string& name);

// The kd-tree as the accelerator (accel/tree_accelerator.hpp) and the local-store model see it. Its
// leaves index the scene's triangles, which must outlive it.
struct KdStructure {
    using Node = KdNode;
    using Traversal = KdTraversal;
    static constexpr const char* kName = "kd";

    static const std::vector<std::string>& traversal_names() { return kd_traversal_names(); }
    static Traversal traversal(const std::string& name) { return kd_traversal(name); }
    template <class Fn>
    static void with_kernel(Traversal t, Fn&& fn) {
        with_kd_kernel(t, std::forward<Fn>(fn));
    }

    KdStructure(std::span<const Triangle> tris, const AccelConfig& config)
        : params(read_kd_params(config)), triangles(tris), tree(build_kdtree(tris, params)) {}
    const Box3& bounds() const { return tree.bounds; }
    std::span<const KdNode> nodes() const { return tree.nodes; }
    std::span<const std::uint32_t> entries() const { return tree.indices; }
    std::span<const Triangle> triangle_array() const { return triangles; }
    std::size_t memory_bytes() const { return nodes().size_bytes() + entries().size_bytes(); }
    std::vector<std::pair<std::string, std::string>> report() const { return kd_report(tree, params); }

    void closest_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<Hit> hits,
                         TraversalCounters* counters) const;
    void any_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const;

    KdBuildParams params;
    std::span<const Triangle> triangles;
    KdTree tree;
};

std::unique_ptr<Accelerator> make_kdtree(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt::detail
