// The SIMD packet kernels with the compiler's generic vectors and no target (4 lanes): builds and
// runs on any processor.
#include "accel/packet_isa.hpp"

namespace cellrt::detail::isa_portable {
constexpr int kLanes = 4;
#include "simd/lanes.inl"
#include "packet/packet_kernels.inl"
#include "accel/packet_table.inl"
}  // namespace cellrt::detail::isa_portable

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_portable() { return isa_portable::kernels(); }
