#include "accel/routed_accelerator.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "bvh/bvh_accel.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/error.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt::detail {
namespace {

const std::vector<std::string> kTraversals{"auto"};

// The calling thread's CPU time in seconds, for a sample's times: it leaves out the time the system
// gave other threads meanwhile, which the wall clock counts (on a busy machine a batch of tens of
// microseconds is often preempted for milliseconds; with three paths a sample holds three chances of
// it). Where the thread clock is missing, the wall clock.
double thread_seconds() {
#if defined(CLOCK_THREAD_CPUTIME_ID)
    timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) == 0)
        return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
#endif
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A path of the route: its name in the report, what traces it, and whether that is a view of another
// path's tree (bvh_with_traversal), whose build and memory the stats count once, with the tree's owner.
struct RoutePath {
    const char* name;
    std::unique_ptr<Accelerator> accel;
    bool view = false;
};

class RoutedAccelerator final : public Accelerator {
public:
    // paths[0] is the packets (the BVH's, or a study tree's) and paths[1] the BVH's single rays, two at
    // a time (coherence names one of them); the measured route may hold views of the BVH's tree traced
    // otherwise (bvh_with_traversal) after them.
    RoutedAccelerator(std::vector<RoutePath> paths, float threshold, std::string packets, bool measured)
        : paths_(std::move(paths)), threshold_(threshold), packets_(std::move(packets)), measured_(measured),
          pickers_{RoutePicker(count(), coherent_left_out()), RoutePicker(count(), incoherent_left_out()),
                   RoutePicker(count(), coherent_left_out()), RoutePicker(count(), incoherent_left_out())} {}

    AccelStats stats() const override {
        const AccelStats c = paths_[0].accel->stats();
        AccelStats s;
        s.name = "auto";
        s.traversal = "auto";
        s.simd_lanes = c.simd_lanes;
        s.triangles = c.triangles;
        for (const RoutePath& p : paths_) {
            if (p.view) continue;  // its tree is another path's
            const AccelStats o = p.accel->stats();
            s.build_seconds += o.build_seconds;
            s.build_cpu_seconds += o.build_cpu_seconds;
            s.memory_bytes += o.memory_bytes;
        }
        s.settings = {{"packets", packets_},
                      {"coherence", param_number(threshold_)},
                      {"route", measured_ ? "measured" : "coherence"},
                      {"streams", holds("stream") ? "on" : "off"},
                      {"bvh_packets", holds("bvh-packets") || packets_ == "bvh" ? "on" : "off"},
                      {"routed", routed()}};
        return s;
    }

private:
    // Batches smaller than this go by coherence alone: their time is too short to read well, and a
    // clock read costs as much as a few rays.
    static constexpr std::size_t kMeasuredBatch = 32;

    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        route(
            rays, 0, [&](const Accelerator& a, TraversalCounters* c) { a.intersect(rays, hits, c); },
            [&] { return static_cast<std::size_t>(std::ranges::count_if(hits, [](const Hit& h) { return h.is_hit(); })); },
            counters);
    }
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        route(
            rays, 1, [&](const Accelerator& a, TraversalCounters* c) { a.occluded(rays, occluded, c); },
            [&] { return static_cast<std::size_t>(std::ranges::count_if(occluded, [](std::uint8_t o) { return o != 0; })); },
            counters);
    }

    // Traces the batch on the path coherence names (the packets or the BVH's single rays) or, when
    // measured, on the one its kind's picker names, timing it when the picker asks (RoutePicker).
    // `query` is 0 for closest hits, 1 for any; `hits` counts the traced batch's hits (or occluded rays).
    template <class Trace, class CountHits>
    void route(std::span<const Ray> rays, int query, Trace&& trace, CountHits&& hits, TraversalCounters* counters) const {
        const int prior = batch_coherence(rays) >= threshold_ ? 0 : 1;
        if (!measured_ || rays.size() < kMeasuredBatch) {
            count_rays(query, prior, rays.size());
            return trace(*paths_[prior].accel, counters);
        }
        const int kind = 2 * query + prior;
        RoutePicker& picker = pickers_[kind];
        const RoutePicker::Choice choice = picker.pick(prior);
        count_rays(query, choice.path, rays.size());
        // The path of this thread's previous batch of the kind: a timed batch counts only when it is
        // the same. On one thread a path's warm-up batch always comes right before; on several, the
        // warm-up may have gone to another core, and this core's caches hold another path's nodes.
        LastPath& last = last_path_[kind];
        const bool warm = last.owner == this && last.path == choice.path;
        last = {this, choice.path};
        const double start = choice.timed ? thread_seconds() : 0.0;
        trace(*paths_[choice.path].accel, counters);
        const double seconds = choice.timed ? thread_seconds() - start : 0.0;
        const std::size_t hit = hits();
        picker.observe(rays.size(), hit);
        if (choice.timed && warm) picker.record(choice.path, seconds, rays.size(), hit);
    }

    void count_rays(int query, int path, std::size_t n) const {
        routed_[query][path].fetch_add(n, std::memory_order_relaxed);
    }
    // Which path answered how many rays so far, per query: "closest packets/paired/stream/bvh-packets,
    // any ..." as fractions, for the benchmark's report of what the route chose; then, per kind of batch that
    // was timed, the batches counted and each path's time per ray in nanoseconds (0: none counted).
    std::string routed() const {
        std::string out;
        for (int q = 0; q < 2; ++q) {
            double n[RoutePicker::kMaxPaths], sum = 0.0;
            for (int p = 0; p < count(); ++p)
                sum += n[p] = static_cast<double>(routed_[q][p].load(std::memory_order_relaxed));
            out += q ? "; any" : "closest";
            // No ray of the query yet: its shares are 0 / 0, not zeros (found by audit, 2026-12-07).
            if (!(sum > 0.0)) {
                out += " none routed";
                continue;
            }
            for (int p = 0; p < count(); ++p) {
                char buf[48];
                std::snprintf(buf, sizeof buf, " %s %.2f", paths_[p].name, n[p] / sum);
                out += buf;
            }
        }
        static const char* const kKinds[4] = {"closest coherent", "closest incoherent", "any coherent", "any incoherent"};
        for (int k = 0; k < 4; ++k) {
            const RoutePicker& picker = pickers_[k];
            if (picker.samples() == 0) continue;
            // The mix the paths' costs are read at: the shares of the kind's rays hitting none, some or
            // all of a batch, over the classes every timed path has; where no class is common to all,
            // every share is 0 and the costs are plain times per ray, which the report says instead of
            // printing zeros as shares (found by audit, 2026-12-07).
            const auto m = picker.mix();
            char mix[96] = "plain times, no class of hit fraction timed on every path";
            if (m[0] + m[1] + m[2] > 0.0)
                std::snprintf(mix, sizeof mix, "costed at shares of rays hitting none/some/all %.2f/%.2f/%.2f", m[0],
                              m[1], m[2]);
            out += std::string("; timed ") + kKinds[k] + " (" + std::to_string(picker.samples()) + " batches, " + mix +
                   "), ns per ray";
            for (int p = 0; p < count(); ++p) {
                if (!picker.takes_part(p)) continue;
                char buf[48];
                std::snprintf(buf, sizeof buf, " %s %.1f", paths_[p].name, 1e9 * picker.cost(p, m));
                out += buf;
            }
        }
        return out;
    }
    bool holds(const std::string& name) const {
        return std::ranges::any_of(paths_, [&](const RoutePath& p) { return name == p.name; });
    }

    int count() const { return static_cast<int>(paths_.size()); }
    // The paths the incoherent batches' pickers leave out: a study tree's packets (RoutePicker),
    // where at least two of the BVH's paths are left to choose between.
    unsigned incoherent_left_out() const { return !paths_[0].view && count() >= 3 ? 1u : 0u; }
    // The paths the coherent batches' pickers leave out: the BVH's single rays (path 1), where at
    // least two other paths are held. Timed on coherent batches in whole frames (direct, AO and
    // diffuse shading, the four shared scenes) they took 1.4 to 5.1 times the fastest path's time
    // per ray (1.4 to 3.7 with packets=bvh) and were never the fastest, and every learning run gave
    // them a share of the camera tiles (docs/INCOHERENT.md, "Twentieth round").
    unsigned coherent_left_out() const { return count() >= 3 ? 2u : 0u; }

    std::vector<RoutePath> paths_;
    float threshold_;
    std::string packets_;
    bool measured_;
    // One per kind of batch: closest or any hit, coherent or not.
    mutable std::array<RoutePicker, 4> pickers_;
    // Per thread and kind of batch, the router and the path of the thread's last batch (route()).
    struct LastPath {
        const RoutedAccelerator* owner = nullptr;
        int path = -1;
    };
    static thread_local std::array<LastPath, 4> last_path_;
    mutable std::atomic<std::uint64_t> routed_[2][RoutePicker::kMaxPaths]{};  // rays answered, per query and path
};

thread_local std::array<RoutedAccelerator::LastPath, 4> RoutedAccelerator::last_path_;

}  // namespace

// Every (n - 1) / kPairs-th pair, 17 of a batch of 256 rays, tells a batch of camera or shadow rays
// (a mean cosine near 1) from AO rays and bounces (below 0.6) as kPairs = 64 (85 pairs) did, for a
// fifth of the work: those held 3.1 % of `perf`'s samples of `auto` on the teapot's random rays,
// these 1.2 % (docs/INCOHERENT.md, "Twenty-first round").
float batch_coherence(std::span<const Ray> rays) {
    constexpr std::size_t kPairs = 16;
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
        {"packets", choice, "kd", 0, 0, {"kd", "bih", "bih-sah", "bvh"},
         "the tree whose SIMD packets trace coherent batches: the kd-tree, the study's BIH, the BIH built "
         "by the SAH (bih@split=sah), or the wide BVH itself (bvh:packet: one tree, no second build, and "
         "bvh_packets is on, and off is refused)"},
        {"coherence", number, "0.9", -1, 1, {},
         "a batch whose neighbouring rays' directions have at least this mean cosine goes to the packets, "
         "any other to the wide BVH (with route=measured: the first guess for its kind of batch)"},
        {"route", choice, "measured", 0, 0, {"measured", "coherence"},
         "measured: each kind of batch (closest or any hit, coherent or not) goes to the path that took "
         "the least time per ray over runs of such batches given to each path in turn; coherence: by "
         "coherence alone, the same path (and work counts) in every run"},
        {"streams", boolean, "on", 0, 0, {},
         "on: the measured route also times the wide BVH's stream traversal (bvh:stream) as a path and "
         "takes it for the kinds of batch it traces fastest (AO and many bounces); off: not"},
        {"bvh_packets", boolean, "on", 0, 0, {},
         "on: the measured route also times the wide BVH's packet traversal (bvh:packet) as a path and "
         "takes it for the kinds of batch it traces fastest; off: not"},
    };
    return table;
}

const std::vector<std::string>& routed_traversals() { return kTraversals; }

std::unique_ptr<Accelerator> make_routed(std::span<const Triangle> triangles, const AccelConfig& config) {
    ParamReader params(routed_params(), config, "auto");
    const std::string packets = params.choice("packets");
    const auto threshold = static_cast<float>(params.number("coherence"));
    const bool measured = params.choice("route") == "measured";
    const bool streams = params.boolean("streams");
    const bool bvh_packets = params.boolean("bvh_packets");
    params.finish();
    // With packets=bvh the BVH's packets are the coherent batches' path: they cannot be left out.
    if (packets == "bvh" && !bvh_packets)
        throw Error("auto: bvh_packets=off contradicts packets=bvh, whose packets are the BVH's own (leave "
                    "bvh_packets out, or choose another tree for the packets)");
    // Coherence alone never names the streams or the BVH's packets (below): asked for by name, they
    // would be left out without a word. (With packets=bvh the BVH's packets are the coherent path.)
    const std::pair<const char*, bool> named[] = {{"streams", streams},
                                                  {"bvh_packets", bvh_packets && packets != "bvh"}};
    for (const auto& [name, on] : named)
        if (!measured && on && config.params.count(name))
            throw Error(std::string("auto: ") + name + "=" + config.params.at(name) +
                        " contradicts route=coherence, which times no paths and so holds neither the streams nor "
                        "the BVH's packets (leave " + name + " out, or choose route=measured)");
    choose_traversal(kTraversals, config.traversal, "auto");
    AccelConfig part;
    part.simd = config.simd == "off" ? "auto" : config.simd;  // the packets are the point of the route
    part.threads = config.threads;
    // The BVH's single rays two at a time (bvh:paired): faster than one at a time on incoherent
    // batches, which are the ones this path is for (docs/INCOHERENT.md, "Eleventh round").
    AccelConfig single = part;
    single.kind = "bvh";
    single.traversal = "paired";
    // The packets' tree for each other value of `packets` (checked against the table above): its kind
    // and build parameters; with packets=bvh the BVH's own packets (a view of its tree) instead.
    static const std::map<std::string, AccelConfig> kPacketTrees = {
        {"kd", {.kind = "kd"}}, {"bih", {.kind = "bih"}}, {"bih-sah", {.kind = "bih", .params = {{"split", "sah"}}}}};
    std::unique_ptr<Accelerator> coherent;
    if (const auto tree = kPacketTrees.find(packets); tree != kPacketTrees.end()) {
        part.kind = tree->second.kind;
        part.params = tree->second.params;
        coherent = make_accelerator(triangles, part);
    }
    std::unique_ptr<Accelerator> bvh = make_accelerator(triangles, single);
    const Accelerator& tree_of_bvh = *bvh;
    std::vector<RoutePath> paths;
    if (coherent)
        paths.push_back({"packets", std::move(coherent)});
    else
        paths.push_back({"packets", bvh_with_traversal(tree_of_bvh, "packet"), true});
    paths.push_back({"paired", std::move(bvh)});
    // Coherence alone names neither the streams nor the BVH's packets, so only the measured route
    // holds them: views of the BVH's tree, not further builds (its packets are the first path already
    // where they trace the coherent batches).
    if (streams && measured) paths.push_back({"stream", bvh_with_traversal(tree_of_bvh, "stream"), true});
    if (bvh_packets && measured && !paths[0].view)
        paths.push_back({"bvh-packets", bvh_with_traversal(tree_of_bvh, "packet"), true});
    return std::make_unique<RoutedAccelerator>(std::move(paths), threshold, packets, measured);
}

}  // namespace cellrt::detail
