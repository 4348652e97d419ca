#include "accel/isa_unit.hpp"

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

const BvhKernels& bvh_kernels_for(const AccelConfig& config) {
    switch (parse_isa(config.simd == "off" ? "auto" : config.simd)) {
        case Isa::sse: return bvh_kernels_sse();
        case Isa::avx2: return bvh_kernels_avx2();
        case Isa::avx512: return bvh_kernels_avx512();
        default: return bvh_kernels_portable();
    }
}

}  // namespace cellrt::detail
