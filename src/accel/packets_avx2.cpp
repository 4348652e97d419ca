// The SIMD packet kernels of every listed structure compiled for avx2 (8 lanes), in a target
// region and a namespace of their own.
#include "accel/packet_isa.hpp"

#if defined(__x86_64__)
#pragma GCC push_options
#pragma GCC target("avx2")
namespace cellrt::detail::isa_avx2 {
constexpr int kLanes = 8;
#define CELLRT_SIMD_AVX2
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
#undef CELLRT_SIMD_AVX2
}  // namespace cellrt::detail::isa_avx2
#pragma GCC pop_options

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx2() { return isa_avx2::kernels(); }
#else
const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx2() { return packet_kernels_portable(); }
#endif
