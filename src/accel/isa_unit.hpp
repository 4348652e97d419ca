// What every instruction set's translation unit (kernels_<isa>.cpp: the SIMD packet kernels and the
// wide BVH's kernels) includes before it opens its
// target region and namespace: everything the kernels use from outside, so that nothing included
// inside the region is compiled for that instruction set except the kernels themselves.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "accel/packet_table.hpp"
#include "accel/structures.hpp"
#include "bvh/bvh_kernels.hpp"
#include "kernel/stack_traversal.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {
const PacketKernels& packet_kernels_portable();
const PacketKernels& packet_kernels_sse();
const PacketKernels& packet_kernels_avx2();
const PacketKernels& packet_kernels_avx512();
const BvhKernels& bvh_kernels_portable();
const BvhKernels& bvh_kernels_sse();
const BvhKernels& bvh_kernels_avx2();
const BvhKernels& bvh_kernels_avx512();
}  // namespace cellrt::detail
