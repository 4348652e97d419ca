// The CUDA kernels: one ray per thread, each thread running the host's own per-ray code
// (device_trace.hpp) over the packed tree in global memory, read through L1 and L2 (memory mode (a)
// of docs/GPU.md), or through the study's software caches in the block's shared memory (mode (b),
// shared_cache.hpp).
//
// Persistent threads (Aila & Laine, "Understanding the Efficiency of Ray Traversal on GPUs", HPG
// 2009, section 3.3): the grid is only as large as the device holds at once, and each warp fetches
// the next 32 rays from one global counter until none is left, so a warp whose rays end early takes
// new ones rather than waiting, with its block, for the slowest warp. The traversal itself is their
// while-while loop: descend inner nodes until a leaf, test the leaf, pop (kernel/stack_traversal.hpp).
#pragma once

#include <cuda_runtime.h>

#include <cstdint>
#include <string>
#include <vector>

#include "cuda/cuda_check.cuh"
#include "cuda/device_memory.hpp"
#include "cuda/device_trace.hpp"
#include "cuda/device_tree.hpp"
#include "cuda/shared_cache.hpp"

namespace cellrt::detail {

inline constexpr int kWarp = 32;
inline constexpr int kBlockThreads = 128;

// The batch's sums: nodes, leaves, triangles (64-bit: a frame's counts pass 2^32).
struct DeviceCounts {
    unsigned long long nodes, leaves, triangles;
};

// The persistent loop of one thread over the batch, its rays read through `mem`.
template <class Traits, class Kernel, bool kAny, class Memory>
__device__ void trace_rays(const TreeView<Traits>& view, Memory& mem, const Ray* rays, Hit* hits, std::uint8_t* occluded,
                           std::uint32_t n, std::uint32_t* next, DeviceCounts* counts) {
    const unsigned lane = threadIdx.x % kWarp;
    RayCounters c;
    for (;;) {
        std::uint32_t base = 0;
        if (lane == 0) base = atomicAdd(next, std::uint32_t(kWarp));
        base = __shfl_sync(0xffffffffu, base, 0);
        if (base >= n) break;
        const std::uint32_t i = base + lane;
        if (i >= n) continue;
        if constexpr (kAny) occluded[i] = trace_any<Traits, Kernel>(view, mem, rays[i], c) ? 1 : 0;
        else hits[i] = trace_closest<Traits, Kernel>(view, mem, rays[i], c);
    }
    if (counts) {
        atomicAdd(&counts->nodes, static_cast<unsigned long long>(c.nodes));
        atomicAdd(&counts->leaves, static_cast<unsigned long long>(c.leaves));
        atomicAdd(&counts->triangles, static_cast<unsigned long long>(c.triangles));
    }
}

__device__ inline void add_counts(DeviceCacheCounts& to, const DeviceCacheCounts& c) {
    atomicAdd(&to.hits, c.hits);
    atomicAdd(&to.misses, c.misses);
    atomicAdd(&to.evictions, c.evictions);
    atomicAdd(&to.torn, c.torn);
    atomicAdd(&to.unfilled, c.unfilled);
}

// Memory mode (b): the layouts of a block's two caches, which lie one after the other in its dynamic
// shared memory (the node cache first; each a multiple of 16 bytes long).
struct SharedCaches {
    SharedCacheLayout node_cache, triangle_cache;
};

// kShared: every block first empties its caches, then its threads read the tree through them
// (shared_cache.hpp) and add their lookups to the block's two counts, block_counts[2 * block] (nodes)
// and [2 * block + 1] (triangles).
template <class Traits, class Kernel, bool kAny, bool kShared>
__global__ void __launch_bounds__(kBlockThreads)
    trace_kernel(const std::byte* tree, PackedTree layout, const Ray* rays, Hit* hits, std::uint8_t* occluded,
                 std::uint32_t n, std::uint32_t* next, DeviceCounts* counts, SharedCaches caches,
                 DeviceCacheCounts* block_counts) {
    const TreeView<Traits> view = packed_view<Traits>(tree, layout);
    if constexpr (kShared) {
        extern __shared__ uint4 cache_storage[];
        auto* storage = reinterpret_cast<std::byte*>(cache_storage);
        const SharedCache node_cache(storage, caches.node_cache);
        const SharedCache triangle_cache(storage + caches.node_cache.bytes(), caches.triangle_cache);
        node_cache.clear(threadIdx.x, blockDim.x);
        triangle_cache.clear(threadIdx.x, blockDim.x);
        __syncthreads();
        const CacheAddressMap map = cache_address_map(view, layout.nodes, layout.entries, layout.triangles);
        SharedCacheMemory<typename Traits::Node> mem(node_cache, triangle_cache, map);
        trace_rays<Traits, Kernel, kAny>(view, mem, rays, hits, occluded, n, next, counts);
        add_counts(block_counts[2 * blockIdx.x], mem.node_counts);
        add_counts(block_counts[2 * blockIdx.x + 1], mem.triangle_counts);
    } else {
        DirectMemory<typename Traits::Node> mem = view.memory();
        trace_rays<Traits, Kernel, kAny>(view, mem, rays, hits, occluded, n, next, counts);
    }
}

// Launches the kernel over rays[0, n) in `stream` with a grid of persistent blocks, and adds the work
// counts to `counters` when non-null (waiting for the stream to read them). In mode (b) each block
// has `memory`'s caches in its dynamic shared memory, and the blocks' cache counts are added to
// `cache_stats` (waiting for the stream).
template <class Traits, class Kernel, bool kAny, bool kShared>
void launch_trace(const std::byte* tree, const PackedTree& layout, const Ray* rays, Hit* hits, std::uint8_t* occluded,
                  std::uint32_t n, int multiprocessors, cudaStream_t stream, TraversalCounters* counters,
                  const DeviceMemoryConfig& memory, DeviceCacheStats* cache_stats) {
    if (n == 0) return;
    auto* kernel = &trace_kernel<Traits, Kernel, kAny, kShared>;
    const std::size_t shared_bytes = kShared ? memory.shared_bytes() : 0;
    if constexpr (kShared)
        cuda_check(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, static_cast<int>(shared_bytes)),
                   "cudaFuncSetAttribute (shared-memory caches)");
    int per_sm = 0;
    cuda_check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, kBlockThreads, shared_bytes),
               "cudaOccupancyMaxActiveBlocksPerMultiprocessor");
    if (kShared && per_sm == 0)
        throw Error("the shared-memory caches (" + memory.to_string() + ") leave no room for a block of " +
                    std::to_string(kBlockThreads) + " threads on this device");
    const std::uint32_t needed = (n + kBlockThreads - 1) / kBlockThreads;
    const std::uint32_t resident = static_cast<std::uint32_t>(per_sm > 0 ? per_sm : 1) * multiprocessors;
    const std::uint32_t blocks = needed < resident ? needed : resident;
    // Scratch: the work counts, the warps' fetch counter, then (mode (b)) two cache counts a block.
    const std::size_t kBlockCountsAt = align_up(sizeof(DeviceCounts) + sizeof(std::uint32_t), kPackedAlignment);
    const std::size_t block_count_bytes = kShared ? 2 * std::size_t(blocks) * sizeof(DeviceCacheCounts) : 0;
    StreamBuffer scratch(kBlockCountsAt + block_count_bytes, stream);
    auto* counts = scratch.at<DeviceCounts>(0);
    auto* next = scratch.at<std::uint32_t>(sizeof(DeviceCounts));
    auto* block_counts = scratch.at<DeviceCacheCounts>(kBlockCountsAt);
    cuda_check(cudaMemsetAsync(counts, 0, kBlockCountsAt + block_count_bytes, stream), "cudaMemsetAsync");
    kernel<<<blocks, kBlockThreads, shared_bytes, stream>>>(tree, layout, rays, hits, occluded, n, next,
                                                            counters ? counts : nullptr,
                                                            SharedCaches{memory.node_cache, memory.triangle_cache},
                                                            block_counts);
    cuda_check(cudaGetLastError(), "kernel launch");
    std::vector<DeviceCacheCounts> per_block(kShared ? 2 * std::size_t(blocks) : 0);
    if (kShared)
        cuda_check(cudaMemcpyAsync(per_block.data(), block_counts, block_count_bytes, cudaMemcpyDeviceToHost, stream),
                   "cudaMemcpyAsync (cache counts)");
    DeviceCounts sum{};
    if (counters)
        cuda_check(cudaMemcpyAsync(&sum, counts, sizeof sum, cudaMemcpyDeviceToHost, stream), "cudaMemcpyAsync");
    if (counters || kShared) cuda_check(cudaStreamSynchronize(stream), "kernel");
    if (counters) {
        counters->rays += n;
        counters->nodes += sum.nodes;
        counters->leaves += sum.leaves;
        counters->triangles += sum.triangles;
    }
    if (kShared && cache_stats) {
        for (std::uint32_t b = 0; b < blocks; ++b) {
            cache_stats->node_cache += per_block[2 * b];
            cache_stats->triangle_cache += per_block[2 * b + 1];
        }
        cache_stats->blocks += blocks;
    }
}

}  // namespace cellrt::detail
