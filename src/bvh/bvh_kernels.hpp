// The wide BVH's kernels as the registry hands them to the accelerator: one table per instruction
// set. The kernels themselves (bvh_kernels.inl) are compiled in each set's unit of the registry
// (accel/kernels_<isa>.cpp), beside the SIMD packet kernels, in eight lanes whatever that set's
// packet width; only the BVH's packets hold sixteen rays with AVX-512 (bvh_packet.inl).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "bvh/bvh_build.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {

struct BvhKernels {
    void (*closest)(const BvhTree&, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*any)(const BvhTree&, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
    // The stream traversal (bvh_stream.inl): the batch's rays down the tree together.
    void (*stream_closest)(const BvhTree&, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*stream_any)(const BvhTree&, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
    // The packet traversal (bvh_packet.inl): packet_rays consecutive rays of the batch, one per lane
    // (eight; sixteen on AVX-512).
    void (*packet_closest)(const BvhTree&, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*packet_any)(const BvhTree&, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
    int packet_rays;
    // Two rays of the batch walked at once (bvh_kernels.inl, paired_batch).
    void (*paired_closest)(const BvhTree&, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*paired_any)(const BvhTree&, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
    const char* isa;  // the instruction set they are compiled for
};

}  // namespace cellrt::detail
