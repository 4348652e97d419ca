// The BIH behind the accelerator boundary (`--accel bih`).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "bih_traversal.hpp"
#include "cellrt/accel.hpp"

namespace cellrt::detail {

struct PacketKernels;

// `-P` build parameters of `config`, validated (docs/BIH.md); throws cellrt::Error naming a bad one.
BihBuildParams read_bih_params(const AccelConfig& config);
// The single-ray traversals by name, the default first, and the one a name selects.
const std::vector<std::string>& bih_traversal_names();
BihTraversal bih_traversal(const std::string& name);

// The BIH as the accelerator (accel/tree_accelerator.hpp) and the local-store model see it. It keeps
// its own reordered copy of the triangles.
struct BihStructure {
    using Node = BihNode;
    using Traversal = BihTraversal;
    static constexpr const char* kName = "bih";

    static const std::vector<std::string>& traversal_names() { return bih_traversal_names(); }
    static Traversal traversal(const std::string& name) { return bih_traversal(name); }
    template <class Fn>
    static void with_kernel(Traversal t, Fn&& fn) {
        with_bih_kernel(t, std::forward<Fn>(fn));
    }

    BihStructure(std::span<const Triangle> tris, const AccelConfig& config)
        : params(read_bih_params(config)), tree(build_bih(tris, params)) {}
    const Box3& bounds() const { return tree.bounds; }
    std::span<const BihNode> nodes() const { return tree.nodes; }
    std::span<const std::uint32_t> entries() const { return tree.prims; }
    std::span<const Triangle> triangle_array() const { return tree.triangles; }
    std::size_t memory_bytes() const {
        return nodes().size_bytes() + entries().size_bytes() + triangle_array().size_bytes();
    }
    std::vector<std::pair<std::string, std::string>> report() const { return bih_report(tree, params); }

    void closest_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<Hit> hits,
                         TraversalCounters* counters) const;
    void any_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const;

    BihBuildParams params;
    BihTree tree;
};

std::unique_ptr<Accelerator> make_bih(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt::detail
