// `--accel auto`: cellrt's fastest exact path for a mix of coherent and incoherent batches. It holds
// two exact structures, SIMD packets over a study tree (fastest on coherent batches: a frame's primary
// rays, shadow rays toward one light) and the wide BVH (fastest on incoherent ones: diffuse bounces,
// AO, random queries), the latter traced one ray at a time or as a stream (unless streams=off)
// (bvh_stream.inl: the batch's rays down the tree together), and routes each batch by its coherence
// and by the time per ray each path has taken on batches of its kind (docs/BVH.md, docs/INCOHERENT.md).
// Every path returns the brute-force hits, so the answers, and images, do not depend on the route.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt::detail {

std::unique_ptr<Accelerator> make_routed(std::span<const Triangle> triangles, const AccelConfig& config);
const ParamTable& routed_params();
const std::vector<std::string>& routed_traversals();

// Which of the router's paths (two, or three with the BVH's streams) traces the next batch of one
// kind (closest or any hit, coherent or not): the one that has taken the least time per ray on the
// batches of that kind that were timed. Every path is exact, so the choice changes the time, never an
// answer, and every batch is traced once.
//
// A path is timed over a run of kRun consecutive batches of the kind, not on one batch traced by two
// paths: a path that traces a kind's batches keeps its nodes warm in the caches, and a path timed on
// a single batch in between finds them cold. Paired samples of that kind chose wrong on three of
// sixteen workloads with the streams (docs/INCOHERENT.md, "Ray streams"). In a run, a thread's batch
// counts only when that thread's previous batch of the kind went on the same path (route()'s
// warm-up), so every counted time is a warm one, as the chosen path's would be.
//
// Runs of neighbouring batches hold similar rays (a frame's tiles in order; a stream of bounces from
// neighbouring pixels), but a background tile costs a tenth of one on the object: so while it learns,
// the picker gives the runs to the paths in turn (each block of `paths` runs one to each path, in an
// order drawn by a hash of the block), which spreads each path's runs over the same stretch of
// batches, and a path's cost is its total time over its total rays.
//
// The first kPrior batches of a kind go by coherence alone (the prior), so that a short run, a C or
// Python caller's one query, pays nothing for the choice. After kLearnRuns runs per path, the fastest
// path takes every run but one in kSample, chosen by a hash of the run's number (not every n-th,
// which would sample the same column of a frame's tiles); that run is timed on a path drawn by the
// hash, the fastest included, so that every estimate keeps up with the workload. A path that costs
// more than kFar times the fastest keeps only one in kSampleFar / kSample of the runs drawn for it
// (the others go to the fastest, timed): a clear loser costs little, while two paths within kFar of
// each other are both timed often. Times are the thread's CPU time, so a batch whose thread the
// system preempted does not count the other threads' time. Sums are atomics: any number of threads
// route and record at once, and a race only blurs a figure.
class RoutePicker {
public:
    static constexpr std::uint64_t kPrior = 8, kRun = 4, kLearnRuns = 8, kSample = 16, kSampleFar = 64;
    static constexpr double kFar = 1.5;
    static constexpr int kMaxPaths = 3;

    explicit RoutePicker(int paths = 2) : paths_(paths < 2 ? 2 : (paths > kMaxPaths ? kMaxPaths : paths)) {}

    int paths() const { return paths_; }
    // The batches counted for `path`, their time in seconds and their rays.
    std::uint64_t samples(int path) const { return samples_[path].load(std::memory_order_relaxed); }
    double seconds(int path) const { return seconds_[path].load(std::memory_order_relaxed); }
    double rays(int path) const { return rays_[path].load(std::memory_order_relaxed); }
    std::uint64_t samples() const {
        std::uint64_t n = 0;
        for (int p = 0; p < paths_; ++p) n += samples(p);
        return n;
    }
    // A path's time per ray over its counted batches; 0 when it has none.
    double cost(int path) const {
        const double n = rays(path);
        return n > 0.0 ? seconds(path) / n : 0.0;
    }

    struct Choice {
        int path;           // 0: the packets, 1: the BVH's single rays, 2: the BVH's streams
        bool timed;         // the batch belongs to a timed run: time it and record() it once warm
    };

    Choice pick(int prior) {
        const std::uint64_t n = batches_.fetch_add(1, std::memory_order_relaxed);
        if (n < kPrior) return {prior, false};
        const std::uint64_t run = (n - kPrior) / kRun, paths = static_cast<std::uint64_t>(paths_);
        if (run < kLearnRuns * paths) {
            // Each block of `paths` runs gives one to every path, rotated by a hash of the block's
            // number: in turn, but not in step with a frame's rows (two paths taking runs strictly
            // by turns gave one the left half of every row of tiles and the other the right half).
            return {static_cast<int>((run + mix(run / paths)) % paths), true};
        }
        const int fast = fastest(prior);
        const std::uint64_t h = mix(run);
        if (h % kSample != 0) return {fast, false};
        int path = static_cast<int>((h >> 16) % paths);
        if (path != fast && far(path, fast) && (h >> 32) % (kSampleFar / kSample) != 0) path = fast;
        return {path, true};
    }
    // The path of least time per ray among those with counted batches; the prior while none has.
    int fastest(int prior) const {
        int fast = -1;
        for (int p = 0; p < paths_; ++p)
            if (cost(p) > 0.0 && (fast < 0 || cost(p) < cost(fast))) fast = p;
        return fast < 0 ? prior : fast;
    }
    // Whether `path` costs more than kFar times `fast` (a path with nothing counted does not).
    bool far(int path, int fast) const { return cost(fast) > 0.0 && cost(path) > kFar * cost(fast); }
    // A warm batch of a timed run: its path, its thread's CPU time and its rays.
    void record(int path, double seconds, std::size_t rays) {
        add(seconds_[path], seconds);
        add(rays_[path], static_cast<double>(rays));
        samples_[path].fetch_add(1, std::memory_order_relaxed);
    }

private:
    // SplitMix64's finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
    // OOPSLA 2014): independent-looking bits for consecutive run numbers.
    static std::uint64_t mix(std::uint64_t x) {
        x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
        x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
        return x ^ (x >> 31);
    }
    static void add(std::atomic<double>& sum, double x) {
        for (double old = sum.load(std::memory_order_relaxed);
             !sum.compare_exchange_weak(old, old + x, std::memory_order_relaxed);) {
        }
    }

    int paths_;
    std::atomic<std::uint64_t> batches_{0};
    std::atomic<std::uint64_t> samples_[kMaxPaths]{0, 0, 0};
    std::atomic<double> seconds_[kMaxPaths]{0.0, 0.0, 0.0}, rays_[kMaxPaths]{0.0, 0.0, 0.0};
};

// The batch's coherence: the mean cosine between the directions of neighbouring rays, over up to 64
// evenly spaced pairs (1 for parallel rays, about 0 for directions uniform on the sphere). Invalid
// rays are left out; a batch of fewer than two valid rays counts as coherent.
float batch_coherence(std::span<const Ray> rays);

}  // namespace cellrt::detail
