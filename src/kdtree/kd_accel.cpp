#include "kd_accel.hpp"

#include "accel/tree_accelerator.hpp"

namespace cellrt::detail {

KdBuildParams read_kd_params(const AccelConfig& config) {
    ParamReader in(config, "kd");
    KdBuildParams p;
    const double traversal_default = config.simd == "off" ? p.traversal_cost : kKdPacketTraversalCost;
    p.traversal_cost = in.get_number("traversal_cost", traversal_default, 1e-6, 1e6);
    p.intersection_cost = in.get_number("intersection_cost", p.intersection_cost, 1e-6, 1e6);
    p.empty_bonus = in.get_number("empty_bonus", p.empty_bonus, 0.0, 0.99);
    p.max_depth = in.get_int("max_depth", p.max_depth, 0, kKdMaxDepth);
    p.leaf_size = in.get_int("leaf_size", p.leaf_size, 0, 1 << 20);
    const std::string method = in.get_choice("method", "hybrid", {"hybrid", "sweep", "binned"});
    p.method = method == "sweep" ? KdBuildMethod::sweep : method == "binned" ? KdBuildMethod::binned : KdBuildMethod::hybrid;
    p.sweep_below = in.get_int("sweep_below", p.sweep_below, 1, 1 << 30);
    p.bins = in.get_int("bins", p.bins, 4, 4096);
    p.perfect_splits = in.get_bool("perfect_splits", p.perfect_splits);
    p.retract = in.get_bool("retract", p.retract);
    p.max_bad_refines = in.get_int("max_bad_refines", p.max_bad_refines, 0, 64);
    p.threads = config.threads;
    in.finish();
    return p;
}

const std::vector<std::string>& kd_traversal_names() {
    static const std::vector<std::string> names{"branched", "rec", "branchless"};
    return names;
}

KdTraversal kd_traversal(const std::string& name) {
    return name == "rec" ? KdTraversal::rec : name == "branched" ? KdTraversal::branched : KdTraversal::branchless;
}

void KdStructure::closest_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<Hit> hits,
                                  TraversalCounters* counters) const {
    k.kd_closest(tree, triangles.data(), rays, hits, counters);
}

void KdStructure::any_packets(const PacketKernels& k, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                              TraversalCounters* counters) const {
    k.kd_any(tree, triangles.data(), rays, occluded, counters);
}

std::unique_ptr<Accelerator> make_kdtree(std::span<const Triangle> triangles, const AccelConfig& config) {
    return std::make_unique<TreeAccelerator<KdStructure>>(triangles, config, packet_kernels_for(config));
}

}  // namespace cellrt::detail
