// The kernels compiled for AVX2: the SIMD packet kernels of every listed structure (8 lanes) and
// the wide BVH's (eight lanes, in a namespace of their own), in a target region of their own.
#include "accel/isa_unit.hpp"

#if defined(__x86_64__)
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace cellrt::detail::isa_avx2 {
constexpr int kLanes = 8;
#define CELLRT_SIMD_AVX2
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
namespace wide {
constexpr int kLanes = kBvhWidth;
#include "simd/lanes.inl"
#include "bvh/bvh_kernels.inl"
#include "bvh/bvh_packet.inl"
}  // namespace wide
#undef CELLRT_SIMD_AVX2
}  // namespace cellrt::detail::isa_avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx2() { return isa_avx2::kernels(); }
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx2() { return isa_avx2::wide::bvh_kernels("avx2"); }
#else
const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx2() { return packet_kernels_portable(); }
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx2() { return bvh_kernels_portable(); }
#endif
