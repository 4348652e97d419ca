// A tree structure behind the accelerator interface: built once and timed, then traced by its
// single-ray kernels over direct memory or by its SIMD packets. One class serves every tree through
// its descriptor `S` (kdtree/kd_structure.hpp describes the members).
#pragma once

#include <memory>
#include <string>

#include "accel/packet_table.hpp"
#include "core/timer.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt::detail {

template <class S>
class TreeAccelerator final : public Accelerator {
public:
    // Every option is validated before the build: the traversal here, the SIMD set by the caller (in
    // `packets`), the parameters by S's constructor before it builds.
    TreeAccelerator(std::span<const Triangle> triangles, const AccelConfig& config, const PacketKernels* packets)
        : traversal_name_(choose_traversal(names_of(S::kTraversals), config.traversal, S::kName)),
          traversal_(value_named(S::kTraversals, traversal_name_, "traversal")),
          packets_(packets ? &packets->template tree<typename S::Traits>() : nullptr),
          lanes_(packets ? packets->lanes : 0),
          structure_(build(triangles, config)) {}

    AccelStats stats() const override {
        AccelStats s;
        s.name = S::kName;
        s.traversal = packets_ ? "packet" : traversal_name_;
        s.simd_lanes = lanes_;
        s.build_seconds = build_seconds_;
        s.build_cpu_seconds = build_cpu_seconds_;
        s.memory_bytes = structure_.memory_bytes();
        s.triangles = structure_.triangle_array().size();
        s.tree = structure_.report();
        s.settings = structure_.settings();
        return s;
    }

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        if (packets_) return packets_->closest(structure_.view(), rays, hits, counters);
        with_direct_kernel([&](auto& kernel) { closest_hits(structure_.bounds(), rays, hits, counters, kernel); });
    }

    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        if (packets_) return packets_->any(structure_.view(), rays, occluded, counters);
        with_direct_kernel([&](auto& kernel) { any_hits(structure_.bounds(), rays, occluded, counters, kernel); });
    }

    S build(std::span<const Triangle> triangles, const AccelConfig& config) {
        Timer timer;
        S s(triangles, config);
        build_seconds_ = timer.seconds();
        build_cpu_seconds_ = timer.cpu_seconds();
        return s;
    }

    // Calls `batch(kernel)` with the chosen traversal over direct memory as kernel(ray, query, counters):
    // one dispatch per batch.
    template <class Batch>
    void with_direct_kernel(Batch&& batch) const {
        auto mem = structure_.view().memory();
        S::with_kernel(traversal_, [&](auto kernel) {
            auto over_memory = [&](const TraversalRay& r, auto& q, auto& c) {
                return kernel(structure_.tree, mem, r, q, c);
            };
            batch(over_memory);
        });
    }

    std::string traversal_name_;
    typename S::Traversal traversal_;
    const TreePacketKernels<typename S::Traits>* packets_;
    int lanes_;
    // Before structure_: build() sets them while structure_ is initialised.
    double build_seconds_ = 0.0, build_cpu_seconds_ = 0.0;
    S structure_;
};

}  // namespace cellrt::detail
