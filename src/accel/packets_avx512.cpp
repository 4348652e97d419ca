// The SIMD packet kernels of every listed structure compiled for avx512 (16 lanes), in a target
// region and a namespace of their own.
#include "accel/packet_isa.hpp"

#if defined(__x86_64__)
#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl,avx512dq,avx512bw")
namespace cellrt::detail::isa_avx512 {
constexpr int kLanes = 16;
#define CELLRT_SIMD_AVX512
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
#undef CELLRT_SIMD_AVX512
}  // namespace cellrt::detail::isa_avx512
#pragma GCC pop_options

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx512() { return isa_avx512::kernels(); }
#else
const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_avx512() { return packet_kernels_portable(); }
#endif
