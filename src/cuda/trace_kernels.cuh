// The CUDA kernels: one ray per thread, each thread running the host's own per-ray code
// (device_trace.hpp) over the packed tree in global memory, read through L1 and L2 (memory mode (a)
// of docs/GPU.md).
//
// Persistent threads (Aila & Laine, "Understanding the Efficiency of Ray Traversal on GPUs", HPG
// 2009, section 3.3): the grid is only as large as the device holds at once, and each warp fetches
// the next 32 rays from one global counter until none is left, so a warp whose rays end early takes
// new ones rather than waiting, with its block, for the slowest warp. The traversal itself is their
// while-while loop: descend inner nodes until a leaf, test the leaf, pop (kernel/stack_traversal.hpp).
#pragma once

#include <cuda_runtime.h>

#include <cstdint>

#include "cuda/cuda_check.cuh"
#include "cuda/device_trace.hpp"
#include "cuda/device_tree.hpp"

namespace cellrt::detail {

inline constexpr int kWarp = 32;
inline constexpr int kBlockThreads = 128;

// The batch's sums: nodes, leaves, triangles (64-bit: a frame's counts pass 2^32).
struct DeviceCounts {
    unsigned long long nodes, leaves, triangles;
};

template <class Traits, class Kernel, bool kAny>
__global__ void __launch_bounds__(kBlockThreads) trace_kernel(const std::byte* tree, PackedTree layout, const Ray* rays,
                                                           Hit* hits, std::uint8_t* occluded, std::uint32_t n,
                                                           std::uint32_t* next, DeviceCounts* counts) {
    const TreeView<Traits> view = packed_view<Traits>(tree, layout);
    const unsigned lane = threadIdx.x % kWarp;
    RayCounters c;
    for (;;) {
        std::uint32_t base = 0;
        if (lane == 0) base = atomicAdd(next, std::uint32_t(kWarp));
        base = __shfl_sync(0xffffffffu, base, 0);
        if (base >= n) break;
        const std::uint32_t i = base + lane;
        if (i >= n) continue;
        if constexpr (kAny) occluded[i] = trace_any<Traits, Kernel>(view, rays[i], c) ? 1 : 0;
        else hits[i] = trace_closest<Traits, Kernel>(view, rays[i], c);
    }
    if (counts) {
        atomicAdd(&counts->nodes, static_cast<unsigned long long>(c.nodes));
        atomicAdd(&counts->leaves, static_cast<unsigned long long>(c.leaves));
        atomicAdd(&counts->triangles, static_cast<unsigned long long>(c.triangles));
    }
}

// Launches the kernel over rays[0, n) in `stream` with a grid of persistent blocks, and adds the work
// counts to `counters` when non-null (waiting for the stream to read them).
template <class Traits, class Kernel, bool kAny>
void launch_trace(const std::byte* tree, const PackedTree& layout, const Ray* rays, Hit* hits, std::uint8_t* occluded,
                  std::uint32_t n, int multiprocessors, cudaStream_t stream, TraversalCounters* counters) {
    if (n == 0) return;
    auto* kernel = &trace_kernel<Traits, Kernel, kAny>;
    int per_sm = 0;
    cuda_check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, kBlockThreads, 0),
               "cudaOccupancyMaxActiveBlocksPerMultiprocessor");
    const std::uint32_t needed = (n + kBlockThreads - 1) / kBlockThreads;
    const std::uint32_t resident = static_cast<std::uint32_t>(per_sm > 0 ? per_sm : 1) * multiprocessors;
    const std::uint32_t blocks = needed < resident ? needed : resident;
    StreamBuffer scratch(sizeof(DeviceCounts) + sizeof(std::uint32_t), stream);
    auto* counts = scratch.at<DeviceCounts>(0);
    auto* next = scratch.at<std::uint32_t>(sizeof(DeviceCounts));
    cuda_check(cudaMemsetAsync(counts, 0, sizeof(DeviceCounts) + sizeof(std::uint32_t), stream), "cudaMemsetAsync");
    kernel<<<blocks, kBlockThreads, 0, stream>>>(tree, layout, rays, hits, occluded, n, next,
                                                 counters ? counts : nullptr);
    cuda_check(cudaGetLastError(), "kernel launch");
    if (counters) {
        DeviceCounts sum{};
        cuda_check(cudaMemcpyAsync(&sum, counts, sizeof sum, cudaMemcpyDeviceToHost, stream), "cudaMemcpyAsync");
        cuda_check(cudaStreamSynchronize(stream), "kernel");
        counters->rays += n;
        counters->nodes += sum.nodes;
        counters->leaves += sum.leaves;
        counters->triangles += sum.triangles;
    }
}

}  // namespace cellrt::detail
