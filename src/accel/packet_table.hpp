// The SIMD packet kernels of one instruction set for brute force and every listed tree
// (structures.hpp), chosen once per accelerator (simd/isa.hpp), never per ray.
#pragma once

#include "accel/structures.hpp"
#include "cellrt/accelerator.hpp"
#include "simd/isa.hpp"

namespace cellrt::detail {

const PacketKernels& packet_kernels(Isa isa);

// The kernels `config.simd` asks for; nullptr for "off" (single rays). Throws for an unavailable set.
const PacketKernels* packet_kernels_for(const AccelConfig& config);

}  // namespace cellrt::detail
