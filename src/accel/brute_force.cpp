#include "accel/brute_force_listing.hpp"
#include "cellrt/brute_force.hpp"

#include "core/timer.hpp"
#include "accel/packet_table.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt {
namespace {

class BruteForce final : public Accelerator {
public:
    BruteForce(std::span<const Triangle> triangles, const detail::PacketKernels* packets)
        : triangles_(triangles), packets_(packets ? &packets->brute : nullptr), lanes_(packets ? packets->lanes : 0) {}

    AccelStats stats() const override {
        AccelStats s;
        s.name = "brute";
        s.traversal = packets_ ? "packet" : "loop";
        s.simd_lanes = lanes_;
        s.triangles = triangles_.size();
        return s;
    }

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        if (packets_) return packets_->closest(triangles_, rays, hits, counters);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Ray& ray = rays[i];
            Hit best = miss_for(ray);
            if (is_valid(ray)) {
                const WatertightRay wr(ray);
                for (std::size_t p = 0; p < triangles_.size(); ++p)
                    intersect_closest(wr, ray.tnear, triangles_[p], static_cast<std::uint32_t>(p), best);
            }
            hits[i] = best.is_hit() ? best : Hit{};
        }
        count(rays.size(), counters);
    }

    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        if (packets_) return packets_->any(triangles_, rays, occluded, counters);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Ray& ray = rays[i];
            occluded[i] = 0;
            if (!is_valid(ray)) continue;
            const WatertightRay wr(ray);
            for (const Triangle& tri : triangles_) {
                if (intersect_any(wr, ray.tnear, ray.tfar, tri)) {
                    occluded[i] = 1;
                    break;
                }
            }
        }
        count(rays.size(), counters);
    }

    void count(std::size_t n, TraversalCounters* counters) const {
        if (!counters) return;
        counters->rays += n;
        counters->triangles += n * triangles_.size();
    }
    std::span<const Triangle> triangles_;
    const detail::BrutePacketKernels* packets_;
    int lanes_;
};

}  // namespace

const ParamTable& brute_force_params() {
    static const ParamTable none;
    return none;
}

const std::vector<std::string>& brute_force_traversals() {
    static const std::vector<std::string> names{"loop"};
    return names;
}

std::unique_ptr<Accelerator> make_brute_force(std::span<const Triangle> triangles, const AccelConfig& config) {
    detail::ParamReader params(brute_force_params(), config, "brute");
    params.finish();
    detail::choose_traversal(brute_force_traversals(), config.traversal, "brute");
    check_finite(triangles);  // again, for callers outside the registry
    return std::make_unique<BruteForce>(triangles, detail::packet_kernels_for(config));
}

}  // namespace cellrt
