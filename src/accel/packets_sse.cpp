// The SIMD packet kernels of every listed structure compiled for sse (4 lanes), in a target
// region and a namespace of their own.
#include "accel/packet_isa.hpp"

#if defined(__x86_64__)
#pragma GCC push_options
#pragma GCC target("sse4.2")
namespace cellrt::detail::isa_sse {
constexpr int kLanes = 4;
#define CELLRT_SIMD_SSE
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
#undef CELLRT_SIMD_SSE
}  // namespace cellrt::detail::isa_sse
#pragma GCC pop_options

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_sse() { return isa_sse::kernels(); }
#else
const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_sse() { return packet_kernels_portable(); }
#endif
