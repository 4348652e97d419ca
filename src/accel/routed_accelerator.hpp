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
// that kind that were sampled. Every path is exact, so a batch can be traced twice, with the same
// answers: a sampled batch is traced by the packets (path 0) and by one other path, its partner, and
// the two times are a paired sample, free of the spread between batches (a tile of background against
// one of the object is a factor of ten, more than the paths differ). Each other path's cost is its
// time over the packets' time on the samples it was partner of; the packets' is 1. With three paths
// the partners take turns: the BVH's single rays and its streams are never timed one right after the
// other on the same rays, which would find the same tree's nodes in the cache and favour whichever
// ran second (measured: it made the streams look 10 % faster than single rays where they are 26 %
// slower, and faster than the packets on a frame's shadow rays, where they are slower). The packets
// trace another tree, so neither of a pair warms the other's nodes.
//
// The first kPrior batches of a kind go by coherence alone (the prior), so that a short run, a C or
// Python caller's one query, pays nothing for the choice; the next is traced twice to warm caches,
// not counted; then one batch in kLearn is sampled until kLearned samples are in, one in kSample
// after that, and one in kSampleFar while every other path's cost is more than kFar times the
// fastest one's (a clear choice costs little). Sampled batches are picked by a hash of the batch's
// number, not every n-th, which would sample the same column of a frame's tiles. A sample's dearer
// time counts at most kClamp times the cheaper one, so that a batch whose thread the system preempted
// (milliseconds, on a batch of tens of microseconds) cannot outweigh the others. Counts are atomics:
// any number of threads route and record at once, and a race only blurs a figure. The choice changes
// only the time, never an answer.
class RoutePicker {
public:
    static constexpr std::uint64_t kPrior = 8, kLearn = 8, kLearned = 16, kSample = 64, kSampleFar = 512;
    static constexpr double kClamp = 8.0, kFar = 1.5;
    static constexpr int kMaxPaths = 3;

    explicit RoutePicker(int paths = 2) : paths_(paths < 2 ? 2 : (paths > kMaxPaths ? kMaxPaths : paths)) {}

    int paths() const { return paths_; }
    // The recorded samples, and for each partner its total time and the packets' over its samples
    // (clamped as record() says).
    std::uint64_t samples() const { return samples_.load(std::memory_order_relaxed); }
    double seconds(int partner) const { return seconds_[partner].load(std::memory_order_relaxed); }
    double packet_seconds(int partner) const { return packets_[partner].load(std::memory_order_relaxed); }
    // A path's cost: its time over the packets' on the same samples (the packets: 1); 0 when unknown.
    double cost(int path) const {
        if (path == 0) return 1.0;
        const double p = packet_seconds(path);
        return p > 0.0 ? seconds(path) / p : 0.0;
    }

    struct Choice {
        int path;      // 0: the packets, 1: the BVH's single rays, 2: the BVH's streams
        bool sampled;  // trace the batch on the packets and on `partner` and record their times
        bool counts;   // whether the sample is recorded (not the first, which warms up)
        int partner;   // the other path of a sampled batch (1 or 2)
    };

    Choice pick(int prior) {
        const std::uint64_t n = batches_.fetch_add(1, std::memory_order_relaxed);
        const int partner = paths_ == 3 ? 1 + static_cast<int>(turn_.load(std::memory_order_relaxed) & 1) : 1;
        if (n < kPrior) return {prior, false, false, partner};
        double c[kMaxPaths];
        bool known = false;
        for (int p = 0; p < paths_; ++p) {
            c[p] = cost(p);
            if (p > 0 && c[p] > 0.0) known = true;
        }
        int fast = prior;  // nothing recorded yet: the prior
        if (known) {
            if (c[fast] == 0.0) fast = 0;
            for (int p = 0; p < paths_; ++p)
                if (c[p] > 0.0 && c[p] < c[fast]) fast = p;
        }
        if (n == kPrior) return {fast, true, false, partner};
        bool far = known;
        for (int p = 0; p < paths_; ++p)
            if (p != fast && !(c[p] > kFar * c[fast])) far = false;  // an unknown cost (0) is not far
        const std::uint64_t period =
            samples_.load(std::memory_order_relaxed) < kLearned ? kLearn : (far ? kSampleFar : kSample);
        return {fast, (n * 0x9e3779b97f4a7c15ull >> 40) % period == 0, true, partner};
    }
    // One sample: the packets' time and the partner's on one batch.
    void record(int partner, double packets, double seconds) {
        const double bound = kClamp * (packets < seconds ? packets : seconds);
        add(packets_[partner], packets < bound ? packets : bound);
        add(seconds_[partner], seconds < bound ? seconds : bound);
        samples_.fetch_add(1, std::memory_order_relaxed);
        turn_.fetch_add(1, std::memory_order_relaxed);
    }
    void record(double packets, double bvh) { record(1, packets, bvh); }

private:
    static void add(std::atomic<double>& sum, double x) {
        for (double old = sum.load(std::memory_order_relaxed);
             !sum.compare_exchange_weak(old, old + x, std::memory_order_relaxed);) {
        }
    }

    int paths_;
    std::atomic<std::uint64_t> batches_{0}, samples_{0}, turn_{0};
    // Per partner (index 1 or 2; 0 unused): its time and the packets' over its samples.
    std::atomic<double> seconds_[kMaxPaths]{0.0, 0.0, 0.0}, packets_[kMaxPaths]{0.0, 0.0, 0.0};
};

// The batch's coherence: the mean cosine between the directions of neighbouring rays, over up to 64
// evenly spaced pairs (1 for parallel rays, about 0 for directions uniform on the sphere). Invalid
// rays are left out; a batch of fewer than two valid rays counts as coherent.
float batch_coherence(std::span<const Ray> rays);

}  // namespace cellrt::detail
