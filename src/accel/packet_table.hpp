// The kernels of one instruction set, chosen once per accelerator (simd/isa.hpp), never per ray: the
// SIMD packet kernels for brute force and every listed tree (structures.hpp), and the wide BVH's.
#pragma once

#include "accel/structures.hpp"
#include "bvh/bvh_kernels.hpp"
#include "cellrt/accelerator.hpp"
#include "simd/isa.hpp"

namespace cellrt::detail {

const PacketKernels& packet_kernels(Isa isa);

// The kernels `config.simd` asks for; nullptr for "off" (single rays). Throws for an unavailable set.
const PacketKernels* packet_kernels_for(const AccelConfig& config);

// The wide BVH's kernels for `config.simd`: its single-ray kernels always run in SIMD lanes, so "off"
// and "auto" both mean the best set available. Throws for an unavailable set.
const BvhKernels& bvh_kernels_for(const AccelConfig& config);

}  // namespace cellrt::detail
