// The kernels compiled for SSE 4.2: the SIMD packet kernels of every listed structure (4 lanes) and
// the wide BVH's (eight lanes, in a namespace of their own), in a target region of their own.
#include "accel/isa_unit.hpp"

// Eight-float vectors passed by value without AVX: GCC notes that their ABI differs from an AVX
// build's. These functions are internal to this unit (inline, in its own namespace), so no call
// crosses that boundary; CMakeLists.txt compiles the unit with -Wno-psabi (a pragma here misses the
// notes GCC emits without a source location).

#if defined(__x86_64__)
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("sse4.2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("sse4.2")
#endif
namespace cellrt::detail::isa_sse {
constexpr int kLanes = 4;
#define CELLRT_SIMD_SSE
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
namespace wide {
constexpr int kLanes = kBvhWidth;
#include "simd/lanes.inl"
#include "bvh/bvh_kernels.inl"
#include "bvh/bvh_packet.inl"
}  // namespace wide
#undef CELLRT_SIMD_SSE
}  // namespace cellrt::detail::isa_sse
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_sse() { return isa_sse::kernels(); }
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_sse() { return isa_sse::wide::bvh_kernels("sse"); }
#else
const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_sse() { return packet_kernels_portable(); }
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_sse() { return bvh_kernels_portable(); }
#endif
