#include "bih_accel.hpp"

#include "cellrt/timer.hpp"
#include "packet/packet.hpp"

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

namespace {

class BihAccelerator final : public Accelerator {
public:
    BihAccelerator(std::span<const Triangle> triangles, const BihBuildParams& params, BihTraversal traversal,
                   const PacketKernels* packets)
        : params_(params), traversal_(traversal), packets_(packets) {
        Timer timer;
        tree_ = build_bih(triangles, params);
        build_seconds_ = timer.seconds();
    }

    void intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        if (packets_) return packets_->bih_closest(tree_, rays, hits, counters);
        DirectMemory<BihNode> mem = memory();
        with_bih_kernel(traversal_, [&](auto kernel) {
            closest_hits(tree_.bounds, rays, hits, counters,
                         [&](const TraversalRay& r, auto& q, auto& c) { return kernel(tree_, mem, r, q, c); });
        });
    }

    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                  TraversalCounters* counters) const override {
        if (packets_) return packets_->bih_any(tree_, rays, occluded, counters);
        DirectMemory<BihNode> mem = memory();
        with_bih_kernel(traversal_, [&](auto kernel) {
            any_hits(tree_.bounds, rays, occluded, counters,
                     [&](const TraversalRay& r, auto& q, auto& c) { return kernel(tree_, mem, r, q, c); });
        });
    }

    AccelStats stats() const override {
        AccelStats s{"bih", build_seconds_,
                     tree_.nodes.size() * sizeof(BihNode) + tree_.triangles.size() * sizeof(Triangle) +
                         tree_.prims.size() * sizeof(std::uint32_t),
                     {{"traversal", packets_ ? "packet" : traversal_ == BihTraversal::branched ? "branched" : "branchless"},
                      {"simd lanes", packets_ ? std::to_string(packets_->lanes) : "off"}}};
        for (auto& f : bih_report(tree_, params_)) s.figures.push_back(std::move(f));
        return s;
    }

private:
    DirectMemory<BihNode> memory() const { return {tree_.nodes.data(), tree_.prims.data(), tree_.triangles.data()}; }

    BihBuildParams params_;
    BihTraversal traversal_;
    const PacketKernels* packets_;
    BihTree tree_;
    double build_seconds_ = 0.0;
};

}  // namespace

std::unique_ptr<Accelerator> make_bih(std::span<const Triangle> triangles, const AccelConfig& config) {
    const BihBuildParams params = read_bih_params(config);
    const BihTraversal traversal = bih_traversal(traversal_or_default(config, bih_traversal_names(), "bih"));
    return std::make_unique<BihAccelerator>(triangles, params, traversal, packet_kernels_for(config));
}

}  // namespace cellrt::detail
