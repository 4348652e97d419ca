// SIMD ray packets (packet_kernels.inl): the kernels of one instruction set, reached through a table
// chosen once per accelerator (simd/isa.hpp), never per ray.
#pragma once

#include <cstdint>
#include <span>

#include "bih/bih_tree.hpp"
#include "cellrt/accel.hpp"
#include "kdtree/kd_tree.hpp"
#include "simd/isa.hpp"

namespace cellrt::detail {

struct PacketKernels {
    int lanes;
    void (*kd_closest)(const KdTree&, const Triangle*, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*kd_any)(const KdTree&, const Triangle*, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
    void (*bih_closest)(const BihTree&, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*bih_any)(const BihTree&, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
    void (*brute_closest)(std::span<const Triangle>, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*brute_any)(std::span<const Triangle>, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
};

const PacketKernels& packet_kernels(Isa isa);

// The kernels `config.simd` asks for; nullptr for "off" (single rays). Throws for an unavailable set.
const PacketKernels* packet_kernels_for(const AccelConfig& config);

}  // namespace cellrt::detail
