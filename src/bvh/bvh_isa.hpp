// What each instruction set's translation unit of the wide BVH's kernels (bvh_<isa>.cpp) includes
// before it opens its target region and namespace, and the table of kernels each one offers.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "bvh/bvh_build.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {

struct BvhKernels {
    void (*closest)(const BvhTree&, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*any)(const BvhTree&, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
};

// The same kernels with the compiler's generic vectors and no target (any processor), for AVX2, and
// for AVX-512 (eight lanes still, with its 32 registers).
const BvhKernels& bvh_kernels_portable();
const BvhKernels& bvh_kernels_avx2();
const BvhKernels& bvh_kernels_avx512();

}  // namespace cellrt::detail
