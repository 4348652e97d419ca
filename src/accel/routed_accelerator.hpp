// `--accel auto`: cellrt's fastest exact path for a mix of coherent and incoherent batches. It holds
// two exact structures, SIMD packets over a study tree (fastest on coherent batches: a frame's primary
// rays, shadow rays toward one light) and the wide BVH (fastest on incoherent ones: diffuse bounces,
// AO, random queries), the latter traced one ray at a time or, with streams=on, also as a stream
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
// kind (closest or any hit, coherent or not): the one that has taken the least time on the batches of
// that kind that all have traced. Every path is exact, so a batch can be traced by all, with the same
// answers: a sampled batch is, and the times are a paired sample, free of the spread between batches
// (a tile of background against one of the object is a factor of ten, more than the paths differ).
//
// The first kPrior batches of a kind go by coherence alone (the prior), so that a short run, a C or
// Python caller's one query, pays nothing for the choice; the next is traced by all to warm their
// caches, not counted; then one batch in kLearn is sampled until kLearned samples are in, one in
// kSample after that, and one in kSampleFar while every other path has taken more than kFar times the
// fastest one's time (a clear choice costs little). Sampled batches are picked by a hash of the batch's
// number, not every n-th, which would sample the same column of a frame's tiles. A sample's dearer
// times count at most kClamp times the cheapest one, so that a batch whose thread the system preempted
// (milliseconds, on a batch of tens of microseconds) cannot outweigh the others. Counts are atomics:
// any number of threads route and record at once, and a race only blurs a figure. The choice changes
// only the time, never an answer.
class RoutePicker {
public:
    static constexpr std::uint64_t kPrior = 8, kLearn = 8, kLearned = 16, kSample = 64, kSampleFar = 512;
    static constexpr double kClamp = 8.0, kFar = 1.5;
    static constexpr int kMaxPaths = 3;

    explicit RoutePicker(int paths = 2) : paths_(paths < 1 ? 1 : (paths > kMaxPaths ? kMaxPaths : paths)) {}

    int paths() const { return paths_; }

    struct Choice {
        int path;      // 0: the packets, 1: the BVH's single rays, 2: the BVH's streams
        bool sampled;  // trace the batch on every path and record their times
        bool counts;   // whether the sample is recorded (not the first, which warms up)
    };

    Choice pick(int prior) {
        const std::uint64_t n = batches_.fetch_add(1, std::memory_order_relaxed);
        if (n < kPrior) return {prior, false, false};
        double t[kMaxPaths];
        for (int p = 0; p < paths_; ++p) t[p] = seconds_[p].load(std::memory_order_relaxed);
        int fast = prior;  // ties (nothing recorded yet) go to the prior
        for (int p = 0; p < paths_; ++p)
            if (t[p] < t[fast]) fast = p;
        if (n == kPrior) return {fast, true, false};
        bool far = paths_ > 1;
        for (int p = 0; p < paths_; ++p)
            if (p != fast && !(t[p] > kFar * t[fast])) far = false;
        const std::uint64_t period =
            samples_.load(std::memory_order_relaxed) < kLearned ? kLearn : (far ? kSampleFar : kSample);
        return {fast, (n * 0x9e3779b97f4a7c15ull >> 40) % period == 0, true};
    }
    // One sample: each path's time on the batch, seconds[0 .. paths()).
    void record(const double* seconds) {
        double least = seconds[0];
        for (int p = 1; p < paths_; ++p) least = seconds[p] < least ? seconds[p] : least;
        const double bound = kClamp * least;
        for (int p = 0; p < paths_; ++p) add(seconds_[p], seconds[p] < bound ? seconds[p] : bound);
        samples_.fetch_add(1, std::memory_order_relaxed);
    }
    void record(double seconds0, double seconds1) {
        const double s[2] = {seconds0, seconds1};
        record(s);
    }
    void record(double seconds0, double seconds1, double seconds2) {
        const double s[3] = {seconds0, seconds1, seconds2};
        record(s);
    }

private:
    static void add(std::atomic<double>& sum, double x) {
        for (double old = sum.load(std::memory_order_relaxed);
             !sum.compare_exchange_weak(old, old + x, std::memory_order_relaxed);) {
        }
    }

    int paths_;
    std::atomic<std::uint64_t> batches_{0}, samples_{0};
    std::atomic<double> seconds_[kMaxPaths]{0.0, 0.0, 0.0};  // over the recorded samples, per path
};

// The batch's coherence: the mean cosine between the directions of neighbouring rays, over up to 64
// evenly spaced pairs (1 for parallel rays, about 0 for directions uniform on the sphere). Invalid
// rays are left out; a batch of fewer than two valid rays counts as coherent.
float batch_coherence(std::span<const Ray> rays);

}  // namespace cellrt::detail
