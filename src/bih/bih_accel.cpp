#include "bih_accel.hpp"

#include "accel/tree_accelerator.hpp"

namespace cellrt::detail {

BihBuildParams read_bih_params(const AccelConfig& config) {
    ParamReader in(config, "bih");
    BihBuildParams p;
    p.split = in.get_choice("split", "global", {"global", "sah"}) == "sah" ? BihSplit::sah : BihSplit::global;
    p.leaf_size = in.get_int("leaf_size", p.leaf_size, 1, 1 << 20);
    p.max_depth = in.get_int("max_depth", p.max_depth, 1, kBihMaxDepth);
    p.empty_cut = in.get_number("empty_cut", p.empty_cut, 0.0, 1.0);
    p.threads = config.threads;
    in.finish();
    return p;
}

const std::vector<std::string>& bih_traversal_names() {
    static const std::vector<std::string> names{"branched", "branchless"};
    return names;
}

BihTraversal bih_traversal(const std::string& name) {
    return name == "branched" ? BihTraversal::branched : BihTraversal::branchless;
}

void BihStructure::closest_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<Hit> hits,
                                   TraversalCounters* counters) const {
    k.bih_closest(tree, rays, hits, counters);
}

void BihStructure::any_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                               TraversalCounters* counters) const {
    k.bih_any(tree, rays, occluded, counters);
}

std::unique_ptr<Accelerator> make_bih(std::span<const Triangle> triangles, const AccelConfig& config) {
    return std::make_unique<TreeAccelerator<BihStructure>>(triangles, config, packet_kernels_for(config));
}

}  // namespace cellrt::detail
