// The kernels compiled for AVX-512: the SIMD packet kernels of every listed structure (16 lanes),
// the wide BVH's (eight lanes, in a namespace of their own) and its packets of sixteen rays, in a
// target region of their own.
#include "accel/isa_unit.hpp"

#if defined(__x86_64__)
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx512f,avx512vl,avx512dq,avx512bw"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl,avx512dq,avx512bw")
#endif
namespace cellrt::detail::isa_avx512 {
constexpr int kLanes = 16;
#define CELLRT_SIMD_AVX512
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
namespace wide {
constexpr int kLanes = kBvhWidth;
#include "simd/lanes.inl"
#include "bvh/bvh_kernels.inl"
}  // namespace wide
// The wide BVH's packets of sixteen rays, one per lane of this set (bvh_packet.inl), over its
// eight-lane nodes and leaves.
using wide::BoxRay;
using wide::bvh_kernel_table;
using wide::horizontal_min;
using wide::kBvhStackSize;
using wide::kBvhStackSlack;
using wide::LeafRay;
using wide::leaf_ray_of_lane;
using wide::miss_all;
using wide::node_children;
using wide::prefetch_child;
using wide::test_leaf;
using wide::traverse_bvh_from;
#include "bvh/bvh_packet.inl"
#undef CELLRT_SIMD_AVX512
}  // namespace cellrt::detail::isa_avx512
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx512() { return isa_avx512::kernels(); }
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx512() { return isa_avx512::bvh_kernels("avx512"); }
#else
const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx512() { return packet_kernels_portable(); }
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx512() { return bvh_kernels_portable(); }
#endif
