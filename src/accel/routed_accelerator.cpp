#include "accel/routed_accelerator.hpp"

#include <algorithm>
#include <cmath>

#include "cellrt/accel.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt::detail {
namespace {

const std::vector<std::string> kTraversals{"auto"};

class RoutedAccelerator final : public Accelerator {
public:
    RoutedAccelerator(std::unique_ptr<Accelerator> coherent, std::unique_ptr<Accelerator> incoherent, float threshold,
                      std::string packets)
        : coherent_(std::move(coherent)), incoherent_(std::move(incoherent)), threshold_(threshold),
          packets_(std::move(packets)) {}

    AccelStats stats() const override {
        const AccelStats c = coherent_->stats(), i = incoherent_->stats();
        AccelStats s;
        s.name = "auto";
        s.traversal = "auto";
        s.simd_lanes = c.simd_lanes;
        s.build_seconds = c.build_seconds + i.build_seconds;
        s.build_cpu_seconds = c.build_cpu_seconds + i.build_cpu_seconds;
        s.memory_bytes = c.memory_bytes + i.memory_bytes;
        s.triangles = c.triangles;
        s.settings = {{"packets", packets_}, {"coherence", param_number(threshold_)}};
        return s;
    }

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        route(rays).intersect(rays, hits, counters);
    }
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        route(rays).occluded(rays, occluded, counters);
    }

    const Accelerator& route(std::span<const Ray> rays) const {
        return batch_coherence(rays) >= threshold_ ? *coherent_ : *incoherent_;
    }

    std::unique_ptr<Accelerator> coherent_, incoherent_;
    float threshold_;
    std::string packets_;
};

}  // namespace

float batch_coherence(std::span<const Ray> rays) {
    constexpr std::size_t kPairs = 64;
    if (rays.size() < 2) return 1.f;
    const std::size_t step = std::max<std::size_t>(1, (rays.size() - 1) / kPairs);
    float sum = 0.f;
    int pairs = 0;
    for (std::size_t i = 0; i + 1 < rays.size(); i += step) {
        const Vec3 &a = rays[i].dir, &b = rays[i + 1].dir;
        const float c = dot(a, b) / std::sqrt(dot(a, a) * dot(b, b));
        if (!std::isfinite(c)) continue;
        sum += c;
        ++pairs;
    }
    return pairs ? sum / static_cast<float>(pairs) : 1.f;
}

const ParamTable& routed_params() {
    using enum ParamType;
    static const ParamTable table{
        {"packets", choice, "kd", 0, 0, {"kd", "bih"}, "the tree whose SIMD packets trace coherent batches"},
        {"coherence", number, "0.9", -1, 1, {},
         "a batch whose neighbouring rays' directions have at least this mean cosine goes to the packets, "
         "any other to the wide BVH"},
    };
    return table;
}

const std::vector<std::string>& routed_traversals() { return kTraversals; }

std::unique_ptr<Accelerator> make_routed(std::span<const Triangle> triangles, const AccelConfig& config) {
    ParamReader params(routed_params(), config, "auto");
    const std::string packets = params.choice("packets");
    const auto threshold = static_cast<float>(params.number("coherence"));
    params.finish();
    choose_traversal(kTraversals, config.traversal, "auto");
    AccelConfig part;
    part.simd = config.simd == "off" ? "auto" : config.simd;  // the packets are the point of the route
    part.threads = config.threads;
    part.kind = packets;
    std::unique_ptr<Accelerator> coherent = make_accelerator(triangles, part);
    part.kind = "bvh";
    return std::make_unique<RoutedAccelerator>(std::move(coherent), make_accelerator(triangles, part), threshold,
                                               packets);
}

}  // namespace cellrt::detail
