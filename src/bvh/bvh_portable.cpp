// The wide BVH's kernels with the compiler's generic vectors of eight floats and no target: they
// build and run on any processor.
#include "bvh/bvh_isa.hpp"

// Eight-float vectors passed by value without AVX: GCC notes that their ABI differs from an AVX
// build's. These functions are internal to this unit (inline, in its own namespace), so no call
// crosses that boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace cellrt::detail::bvh_portable {
constexpr int kLanes = 8;
#include "simd/lanes.inl"
#include "bvh/bvh_kernels.inl"
}  // namespace cellrt::detail::bvh_portable

const cellrt::detail::BvhKernels& cellrt::detail::bvh_kernels_portable() { return bvh_portable::kernels(); }
