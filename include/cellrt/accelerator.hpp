// The accelerator interface: what every acceleration structure (brute force, kd-tree, BIH, Embree)
// offers the renderer, the scheduler, the bindings and the tests. Calls take a batch of rays (a packet
// or a tile), so the one virtual dispatch is paid per batch, never per ray. The structures and their
// registry are in cellrt/accel.hpp.
//
// Thread safety: intersect(), occluded() and stats() are const and may run at once from any number of
// threads on one accelerator of any kind (each thread of the local-store model is a worker with a
// local store of its own), and every call gets the answers it gets alone. Calls that run at once must
// not share a TraversalCounters (it is summed unsynchronised) nor write overlapping result spans; a
// local-store accelerator's statistics are read between traces (the `cellrt render --local-store`
// model, src/localstore/, not a public header). Destroying an
// accelerator while a call runs on it is undefined, as for any object. What an accelerator keeps of
// the triangles it was built over: cellrt/accel.hpp.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cellrt/ray.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt {

// Per-query work counters, summed over a batch when requested (pass a non-null pointer).
struct TraversalCounters {
    std::uint64_t rays = 0;
    std::uint64_t nodes = 0;      // inner nodes visited
    std::uint64_t leaves = 0;     // leaves visited (brute force: 0)
    std::uint64_t triangles = 0;  // ray-triangle tests

    TraversalCounters& operator+=(const TraversalCounters& o) {
        rays += o.rays; nodes += o.nodes; leaves += o.leaves; triangles += o.triangles;
        return *this;
    }
};

struct AccelConfig {
    std::string kind = "kd";   // see accelerator_kinds()
    std::string traversal;     // empty: the structure's default
    // SIMD packet kernels: "off" (one ray at a time, with `traversal`), "auto" (the best instruction
    // set this binary and processor have), "portable", "sse", "avx2" or "avx512". With packets, each
    // batch is traced kLanes rays at a time (4, 8 or 16), large batches after an entry-point search.
    std::string simd = "off";
    unsigned threads = 0;      // build threads; 0: all hardware threads
    std::map<std::string, std::string> params;  // the structure's build parameters (its ParamTable)
    // Where the rays are traced: "cpu", or "cuda" (the trees' single-ray kernels on the GPU, with simd
    // "off"; cellrt/device.hpp, docs/GPU.md).
    std::string device = "cpu";
};

// A tree's build report (Mitsuba's build statistics): its shape, how often triangles are referenced,
// and its SAH cost, the expected cost of a random ray that meets the root cell, in the cost units of
// the structure's table: the kd-tree's as built (K_T 15 and K_I 20 for single rays, K_T 45 for SIMD
// packets, or what -P set), the BIH's always K_T 15 and K_I 20 (so that it compares with a kd-tree
// built with those), the BVH's its own.
struct TreeReport {
    std::size_t nodes = 0, inner_nodes = 0, leaves = 0, empty_leaves = 0;
    std::optional<std::size_t> empty_space_nodes;  // BIH: inner nodes that cut off empty space
    int depth_limit = 0, max_depth = 0;   // depth_limit 0: none
    double mean_leaf_depth = 0.0;          // over non-empty leaves
    double triangles_per_leaf = 0.0;       // over non-empty leaves
    double references_per_triangle = 0.0;  // leaf entries per scene triangle
    double sah_cost = 0.0;
};

// What a built accelerator reports: typed figures for code, and figures() for people.
struct AccelStats {
    std::string name;             // the kind
    std::string traversal;        // the single-ray kernel, "packet" (SIMD packets), "auto" (the route), or Embree's
    int simd_lanes = 0;           // rays a SIMD packet traces at once; 0: single rays
    double build_seconds = 0.0;
    double build_cpu_seconds = 0.0;  // the process's CPU time over the build, all threads together
    std::size_t memory_bytes = 0;  // what the structure holds; not the triangles it reads in place
    std::size_t triangles = 0;
    std::optional<TreeReport> tree;  // kd-tree, BIH and the wide BVH
    // Whether TraversalCounters' nodes, leaves and triangles are counted; false: rays only (Embree,
    // which reports none), so that a zero there is not read as measured.
    bool counts_work = true;
    // The build settings as used (name, value), in print order: the structure's parameters that shape
    // its build, Embree's flags, the local store's layout. Embree's also carry what it reports beside
    // its flags: its device's set-up time, its peak memory, the counters it keeps and its version.
    std::vector<std::pair<std::string, std::string>> settings;

    // The printed report, in print order, as (name, value): the fields above but the name, the build
    // times and the memory, which a program prints beside it.
    std::vector<std::pair<std::string, std::string>> figures() const;
    // The value of setting `name`, or nullopt.
    std::optional<std::string> setting(const std::string& name) const;
};

class Accelerator {
public:
    virtual ~Accelerator() = default;

    // Closest hit of each ray under the hit rule of ray.hpp (Embree's own test and rule for the
    // `embree` kind: docs/EMBREE.md). Throws cellrt::Error when hits.size()
    // differs from rays.size() (checked once per call, before any ray is traced), and, for Embree,
    // for a ray outside its domain (a negative tnear, a component beyond 1.844e18: docs/EMBREE.md),
    // after which `hits` may be partly written; an exception from the structure (a GPU's failure)
    // may leave it so too.
    void intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters = nullptr) const;

    // Any hit: occluded[i] = 1 when some triangle is hit with tnear <= t <= tfar, else 0. Throws
    // cellrt::Error when occluded.size() differs from rays.size().
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                  TraversalCounters* counters = nullptr) const;

    virtual AccelStats stats() const = 0;

    // Whether some rays are refused (Embree: a negative tnear, a component beyond its range), not
    // answered; every other kind answers every ray. check_rays() throws cellrt::Error for the first
    // ray of `rays` refused, naming it as ray first + i: a caller that traces a large batch in pieces
    // checks each piece with its offset, so that the error names the caller's index (the C API checks
    // the whole batch before tracing any, so that a refusal writes no answer).
    virtual bool refuses_rays() const { return false; }
    virtual void check_rays(std::span<const Ray> rays, std::size_t first = 0) const {
        static_cast<void>(rays);
        static_cast<void>(first);
    }

private:
    // What each structure implements, called by intersect() and occluded() with spans of equal length,
    // so that no structure has to check them again.
    virtual void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const = 0;
    virtual void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                             TraversalCounters* counters) const = 0;
};

}  // namespace cellrt
