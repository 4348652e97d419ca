#include "cellrt/brute_force.hpp"

#include "cellrt/timer.hpp"
#include "packet/packet.hpp"

namespace cellrt {
namespace {

class BruteForce final : public Accelerator {
public:
    BruteForce(std::span<const Triangle> triangles, const detail::PacketKernels* packets)
        : triangles_(triangles), packets_(packets) {}

    void intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        if (packets_) return packets_->brute_closest(triangles_, rays, hits, counters);
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

    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                  TraversalCounters* counters) const override {
        if (packets_) return packets_->brute_any(triangles_, rays, occluded, counters);
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

    AccelStats stats() const override {
        return {"brute", 0.0, 0, {{"triangles", std::to_string(triangles_.size())}}};
    }

private:
    void count(std::size_t n, TraversalCounters* counters) const {
        if (!counters) return;
        counters->rays += n;
        counters->triangles += n * triangles_.size();
    }
    std::span<const Triangle> triangles_;
    const detail::PacketKernels* packets_;
};

}  // namespace

std::unique_ptr<Accelerator> make_brute_force(std::span<const Triangle> triangles, const AccelConfig& config) {
    ParamReader params(config, "brute");
    traversal_or_default(config, {"loop"}, "brute");
    params.finish();
    return std::make_unique<BruteForce>(triangles, detail::packet_kernels_for(config));
}

}  // namespace cellrt
