// The packet kernels with the compiler's generic vectors and no target (4 lanes): builds and
// runs on any processor.
#include "packet_isa.hpp"

namespace cellrt::detail::isa_portable {
constexpr int kLanes = 4;
#include "simd/lanes.inl"
#include "packet_kernels.inl"
}  // namespace cellrt::detail::isa_portable

const cellrt::detail::PacketKernels& cellrt::detail::packet_kernels_portable() { return isa_portable::kernels(); }
