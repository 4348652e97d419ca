// The kernels compiled for no target, with the compiler's generic vectors (any processor): the SIMD packet kernels of every listed structure (4 lanes) and
// the wide BVH's (eight lanes, in a namespace of their own), in a target region of their own.
#include "accel/isa_unit.hpp"

// Eight-float vectors passed by value without AVX: GCC notes that their ABI differs from an AVX
// build's. These functions are internal to this unit (inline, in its own namespace), so no call
// crosses that boundary; CMakeLists.txt compiles the unit with -Wno-psabi (a pragma here misses the
// notes GCC emits without a source location).

namespace cellrt::detail::isa_portable {
constexpr int kLanes = 4;
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
namespace wide {
constexpr int kLanes = kBvhWidth;
#include "simd/lanes.inl"
#include "bvh/bvh_kernels.inl"
#include "bvh/bvh_packet.inl"
}  // namespace wide
}  // namespace cellrt::detail::isa_portable

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_portable() { return isa_portable::kernels(); }
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_portable() { return isa_portable::wide::bvh_kernels("portable"); }
