#include "accel/routed_accelerator.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "cellrt/accel.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt::detail {
namespace {

const std::vector<std::string> kTraversals{"auto"};

class RoutedAccelerator final : public Accelerator {
public:
    RoutedAccelerator(std::unique_ptr<Accelerator> coherent, std::unique_ptr<Accelerator> incoherent, float threshold,
                      std::string packets, bool measured)
        : paths_{std::move(coherent), std::move(incoherent)}, threshold_(threshold), packets_(std::move(packets)),
          measured_(measured) {}

    AccelStats stats() const override {
        const AccelStats c = paths_[0]->stats(), i = paths_[1]->stats();
        AccelStats s;
        s.name = "auto";
        s.traversal = "auto";
        s.simd_lanes = c.simd_lanes;
        s.build_seconds = c.build_seconds + i.build_seconds;
        s.build_cpu_seconds = c.build_cpu_seconds + i.build_cpu_seconds;
        s.memory_bytes = c.memory_bytes + i.memory_bytes;
        s.triangles = c.triangles;
        s.settings = {{"packets", packets_},
                      {"coherence", param_number(threshold_)},
                      {"route", measured_ ? "measured" : "coherence"}};
        return s;
    }

private:
    // Batches smaller than this go by coherence alone: their time is too short to read well, and a
    // clock read costs as much as a few rays.
    static constexpr std::size_t kMeasuredBatch = 32;

    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        route(rays, 0, [&](const Accelerator& a, TraversalCounters* c) { a.intersect(rays, hits, c); }, counters);
    }
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        route(rays, 1, [&](const Accelerator& a, TraversalCounters* c) { a.occluded(rays, occluded, c); }, counters);
    }

    // Traces the batch on the path coherence names or, when measured, on the one its kind's picker
    // names; a sampled batch also on the other path (first or second by turns, so that neither always
    // finds the rays in the cache), without its work counted. `query` is 0 for closest hits, 1 for any.
    template <class Trace>
    void route(std::span<const Ray> rays, int query, Trace&& trace, TraversalCounters* counters) const {
        const int prior = batch_coherence(rays) >= threshold_ ? 0 : 1;
        if (!measured_ || rays.size() < kMeasuredBatch) return trace(*paths_[prior], counters);
        RoutePicker& picker = pickers_[2 * query + prior];
        const RoutePicker::Choice choice = picker.pick(prior);
        if (!choice.sampled) return trace(*paths_[choice.path], counters);
        double seconds[2];
        const int first = turn_.fetch_add(1, std::memory_order_relaxed) & 1;
        for (const int path : {first, 1 - first}) {
            const auto start = std::chrono::steady_clock::now();
            trace(*paths_[path], path == choice.path ? counters : nullptr);
            seconds[path] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        if (choice.counts) picker.record(seconds[0], seconds[1]);
    }

    std::unique_ptr<Accelerator> paths_[2];  // the packets, the BVH
    float threshold_;
    std::string packets_;
    bool measured_;
    // One per kind of batch: closest or any hit, coherent or not.
    mutable std::array<RoutePicker, 4> pickers_;
    mutable std::atomic<unsigned> turn_{0};
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
         "any other to the wide BVH (with route=measured: the first guess for its kind of batch)"},
        {"route", choice, "measured", 0, 0, {"measured", "coherence"},
         "measured: each kind of batch (closest or any hit, coherent or not) goes to the path that took "
         "less time on a sample of them, traced by both; coherence: by coherence alone, the same path "
         "(and work counts) in every run"},
    };
    return table;
}

const std::vector<std::string>& routed_traversals() { return kTraversals; }

std::unique_ptr<Accelerator> make_routed(std::span<const Triangle> triangles, const AccelConfig& config) {
    ParamReader params(routed_params(), config, "auto");
    const std::string packets = params.choice("packets");
    const auto threshold = static_cast<float>(params.number("coherence"));
    const bool measured = params.choice("route") == "measured";
    params.finish();
    choose_traversal(kTraversals, config.traversal, "auto");
    AccelConfig part;
    part.simd = config.simd == "off" ? "auto" : config.simd;  // the packets are the point of the route
    part.threads = config.threads;
    part.kind = packets;
    std::unique_ptr<Accelerator> coherent = make_accelerator(triangles, part);
    part.kind = "bvh";
    return std::make_unique<RoutedAccelerator>(std::move(coherent), make_accelerator(triangles, part), threshold,
                                               packets, measured);
}

}  // namespace cellrt::detail
