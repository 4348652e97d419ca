// The accelerator boundary: what every acceleration structure (brute force, kd-tree, BIH, Embree)
// offers the renderer, the scheduler and the tests. Calls take a batch of rays (a packet or a
// tile), so the one virtual dispatch is paid per batch, never per ray.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
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
    std::map<std::string, std::string> params;  // structure-specific build parameters, name -> value
};

// Build report: time, memory and structure-specific figures in print order.
struct AccelStats {
    std::string name;
    double build_seconds = 0.0;
    std::size_t memory_bytes = 0;
    std::vector<std::pair<std::string, std::string>> figures;
};

class Accelerator {
public:
    virtual ~Accelerator() = default;

    // Closest hit of each ray under the hit rule of ray.hpp; hits.size() must equal rays.size().
    virtual void intersect(std::span<const Ray> rays, std::span<Hit> hits,
                           TraversalCounters* counters = nullptr) const = 0;

    // Any hit: occluded[i] = 1 when some triangle is hit with tnear <= t <= tfar, else 0.
    virtual void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                          TraversalCounters* counters = nullptr) const = 0;

    virtual AccelStats stats() const = 0;
};

// Builds the structure `config.kind` over `triangles` (which must outlive the accelerator).
// Throws cellrt::Error for an unknown kind, traversal or parameter, or a parameter out of range.
std::unique_ptr<Accelerator> make_accelerator(std::span<const Triangle> triangles, const AccelConfig& config);

// An accelerator configuration written as one string, as the benchmarks and tests name them:
// KIND[:TRAVERSAL][+SIMD][@NAME=VALUE,...], e.g. "kd:rec", "bih+avx2", "kd+auto@leaf_size=2,bins=64".
// Throws cellrt::Error for a malformed parameter; the parts themselves are checked by make_accelerator.
AccelConfig parse_accel_config(std::string spec);

// Kinds built into this binary ("brute", "kd", "bih", and "embree" where Embree 3 was found).
std::vector<std::string> accelerator_kinds();

// Reads and validates structure parameters (Mitsuba style: each has a name, a default and a range;
// an unknown name or a bad value is an error naming the structure and the parameter).
class ParamReader {
public:
    ParamReader(const AccelConfig& config, std::string structure);
    double get_number(const std::string& name, double default_value, double min_value, double max_value);
    int get_int(const std::string& name, int default_value, int min_value, int max_value);
    bool get_bool(const std::string& name, bool default_value);
    std::string get_choice(const std::string& name, const std::string& default_value,
                           const std::vector<std::string>& choices);
    // Throws for every parameter that no get_* call consumed.
    void finish() const;

private:
    const std::string* take(const std::string& name);
    std::map<std::string, std::string> remaining_;
    std::deque<std::string> consumed_;
    std::string structure_;
};

// Validates config.traversal against `choices` (error names the structure); empty gives choices[0].
std::string traversal_or_default(const AccelConfig& config, const std::vector<std::string>& choices,
                                 const std::string& structure);

}  // namespace cellrt
