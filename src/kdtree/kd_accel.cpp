#include "kd_accel.hpp"

#include "cellrt/timer.hpp"
#include "packet/packet.hpp"

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

namespace {

const char* name(KdTraversal t) {
    return t == KdTraversal::rec ? "rec" : t == KdTraversal::branched ? "branched" : "branchless";
}

class KdAccelerator final : public Accelerator {
public:
    KdAccelerator(std::span<const Triangle> triangles, const KdBuildParams& params, KdTraversal traversal,
                  const PacketKernels* packets)
        : triangles_(triangles), params_(params), traversal_(traversal), packets_(packets) {
        Timer timer;
        tree_ = build_kdtree(triangles, params);
        build_seconds_ = timer.seconds();
    }

    void intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        if (packets_) return packets_->kd_closest(tree_, triangles_.data(), rays, hits, counters);
        DirectMemory<KdNode> mem = memory();
        with_kd_kernel(traversal_, [&](auto kernel) {
            closest_hits(tree_.bounds, rays, hits, counters,
                         [&](const TraversalRay& r, auto& q, auto& c) { return kernel(tree_, mem, r, q, c); });
        });
    }

    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                  TraversalCounters* counters) const override {
        if (packets_) return packets_->kd_any(tree_, triangles_.data(), rays, occluded, counters);
        DirectMemory<KdNode> mem = memory();
        with_kd_kernel(traversal_, [&](auto kernel) {
            any_hits(tree_.bounds, rays, occluded, counters,
                     [&](const TraversalRay& r, auto& q, auto& c) { return kernel(tree_, mem, r, q, c); });
        });
    }

    AccelStats stats() const override {
        AccelStats s{"kd", build_seconds_,
                     tree_.nodes.size() * sizeof(KdNode) + tree_.indices.size() * sizeof(std::uint32_t),
                     {{"traversal", packets_ ? "packet" : name(traversal_)},
                      {"simd lanes", packets_ ? std::to_string(packets_->lanes) : "off"}}};
        for (auto& f : kd_report(tree_, params_)) s.figures.push_back(std::move(f));
        return s;
    }

private:
    DirectMemory<KdNode> memory() const { return {tree_.nodes.data(), tree_.indices.data(), triangles_.data()}; }

    std::span<const Triangle> triangles_;
    KdBuildParams params_;
    KdTraversal traversal_;
    const PacketKernels* packets_;
    KdTree tree_;
    double build_seconds_ = 0.0;
};

}  // namespace

std::unique_ptr<Accelerator> make_kdtree(std::span<const Triangle> triangles, const AccelConfig& config) {
    const KdBuildParams params = read_kd_params(config);
    const KdTraversal traversal = kd_traversal(traversal_or_default(config, kd_traversal_names(), "kd"));
    return std::make_unique<KdAccelerator>(triangles, params, traversal, packet_kernels_for(config));
}

}  // namespace cellrt::detail
