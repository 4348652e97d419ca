// `--accel auto`: cellrt's fastest exact path for a mix of coherent and incoherent batches. It holds
// two exact structures, SIMD packets over a study tree (packets=kd|bih|bih-sah: fastest on a frame's
// square tiles of primary rays and shadow rays toward one light) and the wide BVH (fastest on
// incoherent batches: diffuse bounces, AO, random queries), the latter traced as single rays two at a
// time (bvh:paired), as a stream (unless streams=off; bvh_stream.inl: the batch's rays down the tree
// together) or in packets of eight rays, sixteen on AVX-512 (unless bvh_packets=off; bvh_packet.inl).
// With packets=bvh the BVH's own packets are the coherent batches' path: one tree, one build. It
// routes each batch by its coherence and by the time per ray each path has taken on batches of its
// kind (docs/BVH.md, docs/INCOHERENT.md).
// Every path returns the brute-force hits, so the answers, and images, do not depend on the route.
#pragma once

#include <algorithm>
#include <array>
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

// Which of the router's paths (two to four: the packets, the BVH's single rays, its streams and its
// packets) traces the next batch of one
// kind (closest or any hit, coherent or not): the one that has taken the least time per ray on the
// batches of that kind that were timed. Every path is exact, so the choice changes the time, never an
// answer, and every batch is traced once.
//
// Paths are timed in interleaved runs: kRounds rounds of consecutive batches, each round kPerPath
// batches per path taking part, path after path in an order drawn by a hash of the run; a path's
// first batch of its kPerPath warms its nodes and is not counted, the others are. Neighbouring
// batches hold similar rays (a frame's tiles in order, a stream of bounces from neighbouring
// pixels), and a tile of background costs a tenth of one on the object, so the paths of a run are
// timed on short stretches of batches taken in turn from the same part of the workload. Timed in
// runs of four batches given to each path in turn, eight runs each, the bunny's camera rays gave
// the packets tiles 12 % dearer than the frame's mean and the single rays tiles 24 % cheaper, and
// the route chose the streams, which take 1.4 to 1.5 times as long as the packets
// (docs/INCOHERENT.md, "Fifth round"). The warm-up batch is there because the path that traces a
// kind's batches keeps its nodes in the caches for the next batch, the packets of coherent rays
// most: timed on single batches, path after path, the kd-tree's packets took 1.7 times their own
// time per ray on Sponza's shadow rays; and two counted batches follow it, not one, because with
// one the streams, whose rays fill the first-level cache, lost their lead on Sibenik's AO rays.
// Several threads share a picker, so a run's batches go to whichever thread asks next; the router
// counts a timed batch only when the same thread's previous batch of the kind took the same path.
//
// Which batches a path is timed on still moves its mean: the bunny's camera tiles on the object
// cost ten times those of background, and with 24 counted tiles per path while learning, the
// kd-tree's packets were timed at 106 ns per ray where the whole frame takes them 152, the BVH's
// packets at 128 where it takes them 92 (docs/INCOHERENT.md, sixth round). What sets a tile's cost
// is mostly how many of its rays hit something (a ray that misses leaves in a few nodes), and that
// is known after the batch, the same for every path. So the times are post-stratified: batches
// fall in kStrata classes by their hit fraction (none of its rays hit, some, all: closest hits, or
// occluded rays), a path's time per ray is taken per class of its counted batches, and two paths
// are compared on the classes both were timed in, their times weighted by the share of the kind's
// rays in each class over every batch routed (not only the counted ones), so that both are read on
// the workload's mix (compared()). Classes rather than a line through the hit fraction: a packet of
// rays costs nearly as much when a few of its rays reach the object as when all do, and a straight
// line fitted to that read the teapot's camera tiles the wrong way round. Pairs rather than one mix
// for all: a class that a slow path was never timed in (it joins few runs) would leave that class
// out of every comparison, as the bunny's camera tiles on the object were left out when only the
// paths in contention had been timed there. Where two paths share no class, their plain times per
// ray are compared.
//
// The first kPrior batches of a kind go by coherence alone (the prior), so that a short run, a C or
// Python caller's one query, pays nothing for the choice. Then kLearnRuns runs with every path
// taking part; then the fastest path takes every run but one in kSample, one run drawn by a hash in
// each stretch of kSample runs (not every n-th, which would time the same column of a frame's
// tiles; a hash of each run alone left 46 runs in a row, three of the bunny's frames, untimed);
// that run is timed with the fastest and every path within kFar of it (the paths in contention),
// and a path that costs more than kFar times the fastest joins one of every kSampleFar / kSample of
// them: a clear loser costs little, while two paths within kFar of each other are compared often,
// on the same stretches. While a class holding kCover or more of the kind's rays has not been timed
// on some path in contention (the learning runs saw only part of the workload: the bunny's first
// 152 camera tiles are all background, where the kd-tree's packets, cheapest on misses, kept its
// camera rays for three frames although the BVH's packets take half their time on the object), the
// next run is timed too, and then one after kRelearn runs, twice as many after each further one (up
// to kRelearnDoublings times; never reset), so that a class the runs seldom meet costs a few runs,
// not one in kRelearn for good. Times are the thread's CPU time, so a batch whose thread the system preempted
// does not count the other threads' time. Sums are atomics: any number of threads route and record
// at once, and a race only blurs a figure.
//
// A study tree's packets take no part in the incoherent batches' runs (the router leaves them out,
// RoutePicker's `left_out`): timed there, on every scene and ray kind measured, they cost 1.8 to 4.1
// times the fastest path, and their batches, on another tree than the BVH's, pushed its nodes out of
// the caches for the batches after them. The BVH's packets, which a warm cache helps most, were then
// timed at 121 ns a ray on Sibenik's AO rays where they take 104 alone, behind the streams (118),
// which read each node once per batch; without the kd-tree's runs they were timed at 89 to 95
// (docs/INCOHERENT.md, "Nineteenth round"). Likewise the BVH's single rays take no part in the
// coherent batches' runs where two other paths are held: timed there in whole frames they took 1.4
// to 5.1 times the fastest path's time and never led, and each learning run gave them camera tiles
// (docs/INCOHERENT.md, "Twentieth round").
class RoutePicker {
public:
    static constexpr std::uint64_t kPrior = 8, kRounds = 3, kPerPath = 3, kLearnRuns = 4, kSample = 16, kSampleFar = 64,
                                   kRelearn = 4, kRelearnDoublings = 6;
    static constexpr double kFar = 1.5, kCover = 0.05;
    static constexpr int kMaxPaths = 4;
    // Classes of a batch's hit fraction: none, some, all.
    static constexpr int kStrata = 3;

    // `left_out`: the paths (bits) never chosen nor timed, for a kind of batch that some path is
    // known not to suit (the router's: a study tree's packets on incoherent batches, the BVH's
    // single rays on coherent ones; above); the prior given to pick() must take part. A mask that
    // would leave fewer than two paths is ignored.
    explicit RoutePicker(int paths = 2, unsigned left_out = 0)
        : paths_(paths < 2 ? 2 : (paths > kMaxPaths ? kMaxPaths : paths)),
          left_out_(usable(paths_, left_out & ((1u << paths_) - 1u))) {}

    int paths() const { return paths_; }
    bool takes_part(int path) const { return !(left_out_ >> path & 1u); }
    // Batches per run: in each round, kPerPath per path taking part.
    std::uint64_t run_length() const {
        return kPerPath * kRounds * static_cast<std::uint64_t>(paths_ - __builtin_popcount(left_out_));
    }
    // The batches counted for `path`, their time in seconds and their rays.
    std::uint64_t samples(int path) const { return samples_[path].load(std::memory_order_relaxed); }
    double seconds(int path) const { return sum(seconds_[path]); }
    double rays(int path) const { return sum(rays_[path]); }
    std::uint64_t samples() const {
        std::uint64_t n = 0;
        for (int p = 0; p < paths_; ++p) n += samples(p);
        return n;
    }
    // A path's time per ray at the mix of the classes every timed path shares (mix()), as the router's
    // report gives it (the choice compares paths two at a time, compared()); 0 when it has no counted
    // batch.
    double cost(int path) const { return cost(path, mix()); }
    // The same at a mix computed once for several paths.
    double cost(int path, const std::array<double, kStrata>& m) const {
        const double n = rays(path);
        if (!(n > 0.0)) return 0.0;
        double mixed = 0.0;
        bool any = false;
        for (int c = 0; c < kStrata; ++c) {
            const auto weight = m[static_cast<std::size_t>(c)];
            if (weight == 0.0) continue;
            mixed += weight * load(seconds_[path][c]) / load(rays_[path][c]);
            any = true;
        }
        return any ? mixed : seconds(path) / n;
    }
    // The shares of the kind's rays (every batch observed; before any, the counted ones) in the classes
    // of hit fraction in which every path with counted batches has some: a class that one path lacks
    // is left out for all, so that all are read on the same mix (none left: all zero, and each path's
    // cost is its plain time per ray).
    std::array<double, kStrata> mix() const {
        std::array<double, kStrata> m{};
        std::array<bool, kStrata> missing{};  // by some path with counted batches
        for (int p = 0; p < paths_; ++p) {
            if (!(rays(p) > 0.0)) continue;
            for (std::size_t c = 0; c < kStrata; ++c) {
                const double n = load(rays_[p][c]);
                m[c] += n;
                missing[c] = missing[c] || !(n > 0.0);
            }
        }
        const bool observed = sum(population_) > 0.0;
        double total = 0.0;
        for (std::size_t c = 0; c < kStrata; ++c) {
            if (observed) m[c] = load(population_[c]);
            if (missing[c]) m[c] = 0.0;
            total += m[c];
        }
        if (total > 0.0)
            for (double& x : m) x /= total;
        return m;
    }
    // Two paths' times per ray on the classes both have counted batches in, weighted by the kind's
    // rays in each (every batch observed; before any, the two paths' counted rays); with no class
    // shared, their plain times per ray; 0 for a path with nothing counted.
    std::array<double, 2> compared(int a, int b) const {
        const double na = rays(a), nb = rays(b);
        const std::array<double, 2> plain{na > 0.0 ? seconds(a) / na : 0.0, nb > 0.0 ? seconds(b) / nb : 0.0};
        if (!(na > 0.0) || !(nb > 0.0)) return plain;
        const bool observed = sum(population_) > 0.0;
        double ca = 0.0, cb = 0.0, weights = 0.0;
        for (std::size_t c = 0; c < kStrata; ++c) {
            const double ra = load(rays_[a][c]), rb = load(rays_[b][c]);
            if (!(ra > 0.0) || !(rb > 0.0)) continue;
            const double w = observed ? load(population_[c]) : ra + rb;
            ca += w * load(seconds_[a][c]) / ra;
            cb += w * load(seconds_[b][c]) / rb;
            weights += w;
        }
        if (!(weights > 0.0)) return plain;
        return {ca / weights, cb / weights};
    }
    // Whether a class holding at least kCover of the observed rays has no counted batch of a path in
    // contention: the fastest, or one taking part within kFar of it.
    bool uncovered() const {
        const double total = sum(population_);
        const int fast = fastest(-1);
        if (!(total > 0.0) || fast < 0) return false;
        for (std::size_t c = 0; c < kStrata; ++c) {
            if (load(population_[c]) < kCover * total) continue;
            for (int p = 0; p < paths_; ++p)
                if (takes_part(p) && (p == fast || !far(p, fast)) && !(load(rays_[p][c]) > 0.0)) return true;
        }
        return false;
    }

    struct Choice {
        int path;    // 0: the packets, 1: the BVH's single rays, then its streams and (a study tree's packets
                     // being 0) its own packets, where held
        bool timed;  // a counted batch (not the warm-up) of a timed run: time it and record() it
    };

    Choice pick(int prior) {
        const std::uint64_t n = batches_.fetch_add(1, std::memory_order_relaxed);
        if (n < kPrior) return {prior, false};
        const std::uint64_t length = run_length(), run = (n - kPrior) / length, at = (n - kPrior) % length;
        const std::uint64_t h = mix(run);
        // A run timed for an uncovered class is decided at its first batch (a later one of the run may
        // see the class covered by then); with several threads a batch of the run picked before that
        // is decided goes untimed to the fastest, which only blurs a figure. The back-off is never
        // reset: a class that comes and goes (a path moving in and out of contention) costs no more
        // than one that stays uncovered.
        if (at == 0 && run >= kLearnRuns && run >= next_relearn_.load(std::memory_order_relaxed) && uncovered()) {
            const std::uint64_t times = relearned_.fetch_add(1, std::memory_order_relaxed);
            next_relearn_.store(run + (kRelearn << std::min<std::uint64_t>(times, kRelearnDoublings)),
                                std::memory_order_relaxed);
            relearning_.store(run, std::memory_order_relaxed);
        }
        int in_run[kMaxPaths];
        int k = 0;
        if (run < kLearnRuns) {
            for (int p = 0; p < paths_; ++p)
                if (takes_part(p)) in_run[k++] = p;
        } else {
            const int fast = fastest(prior);
            if (!timed_run(run) && relearning_.load(std::memory_order_relaxed) != run) return {fast, false};
            const bool far_ones_join = far_ones_join_run(run);
            for (int p = 0; p < paths_; ++p)
                if (takes_part(p) && (p == fast || !far(p, fast) || far_ones_join)) in_run[k++] = p;
        }
        // The run's order: a rotation drawn by the hash, so that no path keeps the same columns of a
        // frame's tiles from run to run. A round is kPerPath * k batches; with fewer paths than the
        // run has room for, it is over sooner and the fastest takes the rest untimed.
        const auto round_length = kPerPath * static_cast<std::uint64_t>(k);
        const std::uint64_t round = at / round_length, slot = at % round_length;
        if (round >= kRounds) return {fastest(prior), false};
        const int path = in_run[(slot / kPerPath + (h >> 16)) % static_cast<std::uint64_t>(k)];
        return {path, slot % kPerPath != 0};
    }
    // The path of least time per ray among those with counted batches, each compared with the fastest
    // so far on the classes the two share (compared()); the prior while none has. Compared so, three
    // paths timed in different classes need not be ordered one way (a beats b, b beats c, c beats
    // a); the scan in path order then settles it.
    int fastest(int prior) const {
        int fast = -1;
        for (int p = 0; p < paths_; ++p) {
            if (!(rays(p) > 0.0)) continue;
            if (fast < 0) {
                fast = p;
                continue;
            }
            const auto c = compared(p, fast);
            if (c[0] < c[1]) fast = p;
        }
        return fast < 0 ? prior : fast;
    }
    // Whether `path` costs more than kFar times `fast` on the classes they share (a path with nothing
    // counted does not).
    bool far(int path, int fast) const {
        const auto c = compared(path, fast);
        return c[1] > 0.0 && c[0] > kFar * c[1];
    }
    // A counted batch of a timed run: its path, its thread's CPU time, its rays and how many of them
    // hit (closest hit) or were occluded (any hit).
    void record(int path, double seconds, std::size_t rays, std::size_t hits) {
        if (rays == 0) return;
        const int c = stratum(rays, hits);
        add(seconds_[path][c], seconds);
        add(rays_[path][c], static_cast<double>(rays));
        samples_[path].fetch_add(1, std::memory_order_relaxed);
    }
    // Every batch of the kind, counted or not: its rays and how many of them hit (the classes' shares).
    void observe(std::size_t rays, std::size_t hits) {
        if (rays != 0) add(population_[stratum(rays, hits)], static_cast<double>(rays));
    }

private:
    static int stratum(std::size_t rays, std::size_t hits) { return hits == 0 ? 0 : hits == rays ? 2 : 1; }
    // The timed runs: one in each stretch of kSample runs, at a place drawn by the stretch's hash; the
    // far paths join the timed run of one stretch in each kSampleFar / kSample, drawn likewise.
    static bool timed_run(std::uint64_t run) { return run % kSample == mix(run / kSample) % kSample; }
    static bool far_ones_join_run(std::uint64_t run) {
        constexpr std::uint64_t k = kSampleFar / kSample;
        const std::uint64_t stretch = run / kSample;
        return stretch % k == mix(~(stretch / k)) % k;
    }
    static unsigned usable(int paths, unsigned left_out) {
        return paths - __builtin_popcount(left_out) >= 2 ? left_out : 0u;
    }
    // SplitMix64's finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
    // OOPSLA 2014): independent-looking bits for consecutive run numbers.
    static std::uint64_t mix(std::uint64_t x) {
        x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
        x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
        return x ^ (x >> 31);
    }
    static double load(const std::atomic<double>& x) { return x.load(std::memory_order_relaxed); }
    static double sum(const std::atomic<double> (&x)[kStrata]) {
        double s = 0.0;
        for (const auto& v : x) s += load(v);
        return s;
    }
    static void add(std::atomic<double>& sum, double x) {
        for (double old = sum.load(std::memory_order_relaxed);
             !sum.compare_exchange_weak(old, old + x, std::memory_order_relaxed);) {
        }
    }

    int paths_;
    unsigned left_out_;
    std::atomic<std::uint64_t> batches_{0};
    std::atomic<std::uint64_t> samples_[kMaxPaths]{};
    // Per path and class of hit fraction: the counted batches' seconds and rays.
    std::atomic<double> seconds_[kMaxPaths][kStrata]{}, rays_[kMaxPaths][kStrata]{};
    // Per class of hit fraction: the rays of every batch observed.
    std::atomic<double> population_[kStrata]{};
    // The last run timed for an uncovered class (pick()), none at first; the first run that may be,
    // and how many have been.
    std::atomic<std::uint64_t> relearning_{~std::uint64_t{0}}, next_relearn_{0}, relearned_{0};
};

// The batch's coherence: the mean cosine between the directions of neighbouring rays, over up to 64
// evenly spaced pairs (1 for parallel rays, about 0 for directions uniform on the sphere). Invalid
// rays are left out; a batch of fewer than two valid rays counts as coherent.
float batch_coherence(std::span<const Ray> rays);

}  // namespace cellrt::detail
