// The wide BVH's kernels compiled for AVX-512 (VL): still eight lanes of 256 bits, but with the 32
// vector registers and the mask registers of AVX-512, so the ray's constants stay in registers
// across a node's box tests and a leaf's triangle tests.
#include "bvh/bvh_isa.hpp"

#if defined(__x86_64__)
#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl,avx512dq,avx512bw")
namespace cellrt::detail::bvh_avx512 {
constexpr int kLanes = 8;
#define CELLRT_SIMD_AVX2  // lanes.inl's bits(): eight lanes are one 256-bit register
#include "simd/lanes.inl"
#include "bvh/bvh_kernels.inl"
#undef CELLRT_SIMD_AVX2
}  // namespace cellrt::detail::bvh_avx512
#pragma GCC pop_options

const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx512() { return bvh_avx512::kernels(); }
#else
const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_avx512() { return bvh_kernels_portable(); }
#endif
