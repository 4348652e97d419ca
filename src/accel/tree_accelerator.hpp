// A tree structure (the kd-tree, the BIH) behind the accelerator boundary: built once and timed, then
// traced by its single-ray kernels over direct memory or by its SIMD packets. One class serves both
// structures; what differs is the structure's description `S` (KdStructure in kd_accel.hpp,
// BihStructure in bih_accel.hpp), which the local-store model (src/localstore) runs on too:
//
//   Node, Traversal, kName             the node type, the traversal enum, the --accel name
//   traversal_names(), traversal(n)    the single-ray traversals by name, the default first
//   with_kernel(traversal, fn)         calls fn(kernel), the traversal as a function object
//                                      kernel(tree, memory, ray, query, counters)
//   S(triangles, config)               reads and validates the -P parameters, then builds
//   tree, bounds(), nodes(), entries(), triangle_array()
//                                      the built tree and the three arrays its kernels read
//   memory_bytes(), report()           the structure's size and its build report
//   closest_packets(kernels, ...), any_packets(kernels, ...)
//                                      the SIMD packet kernels' entry points for this structure
#pragma once

#include <memory>
#include <string>

#include "kernel/traversal.hpp"
#include "cellrt/timer.hpp"
#include "packet/packet.hpp"

namespace cellrt::detail {

template <class S>
class TreeAccelerator final : public Accelerator {
public:
    // Every option is validated before the build: the traversal here, the SIMD set by the caller (in
    // `packets`), the parameters by S's constructor before it builds.
    TreeAccelerator(std::span<const Triangle> triangles, const AccelConfig& config, const PacketKernels* packets)
        : traversal_name_(traversal_or_default(config, S::traversal_names(), S::kName)),
          traversal_(S::traversal(traversal_name_)),
          packets_(packets),
          structure_(build(triangles, config)) {}

    void intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        if (packets_) return structure_.closest_packets(*packets_, rays, hits, counters);
        with_direct_kernel([&](auto& kernel) { closest_hits(structure_.bounds(), rays, hits, counters, kernel); });
    }

    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                  TraversalCounters* counters) const override {
        if (packets_) return structure_.any_packets(*packets_, rays, occluded, counters);
        with_direct_kernel([&](auto& kernel) { any_hits(structure_.bounds(), rays, occluded, counters, kernel); });
    }

    AccelStats stats() const override {
        AccelStats s{S::kName, build_seconds_, structure_.memory_bytes(),
                     {{"traversal", packets_ ? "packet" : traversal_name_},
                      {"simd lanes", packets_ ? std::to_string(packets_->lanes) : "off"}}};
        for (auto& f : structure_.report()) s.figures.push_back(std::move(f));
        return s;
    }

private:
    S build(std::span<const Triangle> triangles, const AccelConfig& config) {
        Timer timer;
        S s(triangles, config);
        build_seconds_ = timer.seconds();
        return s;
    }

    // Calls `batch(kernel)` with the chosen traversal over direct memory as kernel(ray, query, counters):
    // one dispatch per batch.
    template <class Batch>
    void with_direct_kernel(Batch&& batch) const {
        DirectMemory<typename S::Node> mem{structure_.nodes().data(), structure_.entries().data(),
                                           structure_.triangle_array().data()};
        S::with_kernel(traversal_, [&](auto kernel) {
            auto over_memory = [&](const TraversalRay& r, auto& q, auto& c) {
                return kernel(structure_.tree, mem, r, q, c);
            };
            batch(over_memory);
        });
    }

    std::string traversal_name_;
    typename S::Traversal traversal_;
    const PacketKernels* packets_;
    double build_seconds_ = 0.0;  // before structure_: build() sets it while structure_ is initialised
    S structure_;
};

}  // namespace cellrt::detail
