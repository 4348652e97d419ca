#include "accel/packet_isa.hpp"

namespace cellrt::detail {

const PacketKernels& packet_kernels(Isa isa) {
    switch (isa) {
        case Isa::sse: return packet_kernels_sse();
        case Isa::avx2: return packet_kernels_avx2();
        case Isa::avx512: return packet_kernels_avx512();
        default: return packet_kernels_portable();
    }
}

const PacketKernels* packet_kernels_for(const AccelConfig& config) {
    if (config.simd == "off") return nullptr;
    return &packet_kernels(parse_isa(config.simd));
}

}  // namespace cellrt::detail
