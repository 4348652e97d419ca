// What every instruction set's translation unit (packet_<isa>.cpp) includes before it opens its
// target region and namespace: everything the kernels use from outside, so that nothing included
// inside the region is compiled for that instruction set except the kernels themselves.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "kernel/traversal.hpp"
#include "bih/bih_traversal.hpp"
#include "kdtree/kd_traversal.hpp"
#include "packet.hpp"

namespace cellrt::detail {
const PacketKernels& packet_kernels_portable();
const PacketKernels& packet_kernels_sse();
const PacketKernels& packet_kernels_avx2();
const PacketKernels& packet_kernels_avx512();
}  // namespace cellrt::detail
