#include "accel/routed_accelerator.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "bvh/bvh_accel.hpp"
#include "cellrt/accel.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt::detail {
namespace {

const std::vector<std::string> kTraversals{"auto"};

class RoutedAccelerator final : public Accelerator {
public:
    // `stream`, when given, traces `incoherent`'s tree as streams (bvh_with_traversal): a third path.
    RoutedAccelerator(std::unique_ptr<Accelerator> coherent, std::unique_ptr<Accelerator> incoherent,
                      std::unique_ptr<Accelerator> stream, float threshold, std::string packets, bool measured)
        : paths_{std::move(coherent), std::move(incoherent), std::move(stream)}, count_(paths_[2] ? 3 : 2),
          threshold_(threshold), packets_(std::move(packets)), measured_(measured),
          pickers_{RoutePicker(count_), RoutePicker(count_), RoutePicker(count_), RoutePicker(count_)} {}

    AccelStats stats() const override {
        const AccelStats c = paths_[0]->stats(), i = paths_[1]->stats();
        AccelStats s;
        s.name = "auto";
        s.traversal = "auto";
        s.simd_lanes = c.simd_lanes;
        s.build_seconds = c.build_seconds + i.build_seconds;
        s.build_cpu_seconds = c.build_cpu_seconds + i.build_cpu_seconds;
        s.memory_bytes = c.memory_bytes + i.memory_bytes;  // the streams trace the BVH's own tree
        s.triangles = c.triangles;
        s.settings = {{"packets", packets_},
                      {"coherence", param_number(threshold_)},
                      {"route", measured_ ? "measured" : "coherence"},
                      {"streams", paths_[2] ? "on" : "off"},
                      {"routed", routed()}};
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

    // Traces the batch on the path coherence names (the packets or the BVH's single rays) or, when
    // measured, on the one its kind's picker names; a sampled batch also on every other path (the
    // first by turns, so that no path always finds the rays in the cache), without its work counted.
    // `query` is 0 for closest hits, 1 for any.
    template <class Trace>
    void route(std::span<const Ray> rays, int query, Trace&& trace, TraversalCounters* counters) const {
        const int prior = batch_coherence(rays) >= threshold_ ? 0 : 1;
        if (!measured_ || rays.size() < kMeasuredBatch) {
            count_rays(query, prior, rays.size());
            return trace(*paths_[prior], counters);
        }
        RoutePicker& picker = pickers_[2 * query + prior];
        const RoutePicker::Choice choice = picker.pick(prior);
        count_rays(query, choice.path, rays.size());
        if (!choice.sampled) return trace(*paths_[choice.path], counters);
        double seconds[RoutePicker::kMaxPaths];
        const int first = static_cast<int>(turn_.fetch_add(1, std::memory_order_relaxed) % unsigned(count_));
        for (int i = 0; i < count_; ++i) {
            const int path = (first + i) % count_;
            const auto start = std::chrono::steady_clock::now();
            trace(*paths_[path], path == choice.path ? counters : nullptr);
            seconds[path] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        if (choice.counts) picker.record(seconds);
    }

    void count_rays(int query, int path, std::size_t n) const {
        routed_[query][path].fetch_add(n, std::memory_order_relaxed);
    }
    // Which path answered how many rays so far, per query: "closest packets/single/stream, any ..."
    // as fractions, for the benchmark's report of what the route chose.
    std::string routed() const {
        std::string out;
        for (int q = 0; q < 2; ++q) {
            double n[3], sum = 0.0;
            for (int p = 0; p < 3; ++p) sum += n[p] = static_cast<double>(routed_[q][p].load(std::memory_order_relaxed));
            out += q ? "; any" : "closest";
            for (int p = 0; p < count_; ++p) {
                char buf[48];
                std::snprintf(buf, sizeof buf, " %s %.2f", kPathNames[p], sum > 0.0 ? n[p] / sum : 0.0);
                out += buf;
            }
        }
        return out;
    }
    static constexpr const char* kPathNames[3] = {"packets", "single", "stream"};

    std::unique_ptr<Accelerator> paths_[3];  // the packets, the BVH's single rays, its streams (or null)
    int count_;                              // paths in use: 2, or 3 with streams
    float threshold_;
    std::string packets_;
    bool measured_;
    // One per kind of batch: closest or any hit, coherent or not.
    mutable std::array<RoutePicker, 4> pickers_;
    mutable std::atomic<unsigned> turn_{0};
    mutable std::atomic<std::uint64_t> routed_[2][3]{};  // rays answered, per query and path
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
         "less time on a sample of them, traced by all; coherence: by coherence alone, the same path "
         "(and work counts) in every run"},
        {"streams", choice, "on", 0, 0, {"on", "off"},
         "on: the measured route also samples the wide BVH's stream traversal (bvh:stream) as a third path "
         "and takes it for the kinds of batch it traces fastest; off: packets and single rays only"},
    };
    return table;
}

const std::vector<std::string>& routed_traversals() { return kTraversals; }

std::unique_ptr<Accelerator> make_routed(std::span<const Triangle> triangles, const AccelConfig& config) {
    ParamReader params(routed_params(), config, "auto");
    const std::string packets = params.choice("packets");
    const auto threshold = static_cast<float>(params.number("coherence"));
    const bool measured = params.choice("route") == "measured";
    const bool streams = params.choice("streams") == "on";
    params.finish();
    choose_traversal(kTraversals, config.traversal, "auto");
    AccelConfig part;
    part.simd = config.simd == "off" ? "auto" : config.simd;  // the packets are the point of the route
    part.threads = config.threads;
    part.kind = packets;
    std::unique_ptr<Accelerator> coherent = make_accelerator(triangles, part);
    part.kind = "bvh";
    std::unique_ptr<Accelerator> bvh = make_accelerator(triangles, part);
    // Coherence alone never names the streams, so only the measured route holds them.
    std::unique_ptr<Accelerator> stream = streams && measured ? bvh_with_traversal(*bvh, "stream") : nullptr;
    return std::make_unique<RoutedAccelerator>(std::move(coherent), std::move(bvh), std::move(stream), threshold,
                                               packets, measured);
}

}  // namespace cellrt::detail
