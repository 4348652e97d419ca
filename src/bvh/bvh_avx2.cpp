// The wide BVH's kernels compiled for AVX2: a node's eight boxes and a leaf's eight triangles fill one
// 256-bit register per coordinate.
#include "bvh/bvh_isa.hpp"

#if defined(__x86_64__)
#pragma GCC push_options
#pragma GCC target("avx2")
namespace cellrt::detail::bvh_avx2 {
constexpr int kLanes = 8;
#define CELLRT_SIMD_AVX2
#include "simd/lanes.inl"
#include "bvh/bvh_kernels.inl"
#undef CELLRT_SIMD_AVX2
}  // namespace cellrt::detail::bvh_avx2
#pragma GCC pop_options

const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx2() { return bvh_avx2::kernels(); }
#else
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx2() { return bvh_kernels_portable(); }
#endif
