// CELLRT_HD marks the functions that the CUDA backend compiles for the GPU as well as for the host:
// the geometry, the watertight test and hit rule, and the tree kernels. Under nvcc it is
// `__host__ __device__`; elsewhere it is empty, so the CPU compiles, runs and tests the very same
// source (docs/GPU.md).
#pragma once

#if defined(__CUDACC__)
#define CELLRT_HD __host__ __device__
#else
#define CELLRT_HD
#endif

// CELLRT_NOINLINE keeps a device function a call (nvcc inlines device functions by default); on the
// host it changes nothing.
#if defined(__CUDA_ARCH__)
#define CELLRT_NOINLINE __noinline__
#else
#define CELLRT_NOINLINE
#endif
