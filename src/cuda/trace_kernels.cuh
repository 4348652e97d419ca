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
#include "cuda/device_frame.hpp"
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

__device__ inline void add_counts(DeviceCounts& to, const RayCounters& c) {
    atomicAdd(&to.nodes, static_cast<unsigned long long>(c.nodes));
    atomicAdd(&to.leaves, static_cast<unsigned long long>(c.leaves));
    atomicAdd(&to.triangles, static_cast<unsigned long long>(c.triangles));
}

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
    if (counts) add_counts(*counts, c);
}

__device__ inline void add_counts(DeviceCacheCounts& to, const DeviceCacheCounts& c) {
    atomicAdd(&to.hits, c.hits);
    atomicAdd(&to.misses, c.misses);
    atomicAdd(&to.evictions, c.evictions);
    atomicAdd(&to.torn, c.torn);
    atomicAdd(&to.unfilled, c.unfilled);
    atomicAdd(&to.prefetches, c.prefetches);
    atomicAdd(&to.touch_hits, c.touch_hits);
}

// Memory mode (b): the layouts of a block's two caches, which lie one after the other in its dynamic
// shared memory (the node cache first; each a multiple of 16 bytes long).
struct SharedCaches {
    SharedCacheLayout node_cache, triangle_cache;
    bool async;  // asynchronous access (touch, then wait)
};

// The tree's memory for one block: direct (mode (a)), or (kShared, mode (b)) the block's caches, which
// it first empties; fn(mem) then runs the block's threads, and in mode (b) the caches' counts are
// added to the block's two, block_counts[2 * block] (nodes) and [2 * block + 1] (triangles).
template <class Traits, bool kShared, class Fn>
__device__ void with_block_memory(const TreeView<Traits>& view, const PackedTree& layout, const SharedCaches& caches,
                                  DeviceCacheCounts* block_counts, Fn&& fn) {
    if constexpr (kShared) {
        extern __shared__ uint4 cache_storage[];
        auto* storage = reinterpret_cast<std::byte*>(cache_storage);
        const SharedCache node_cache(storage, caches.node_cache);
        const SharedCache triangle_cache(storage + caches.node_cache.bytes(), caches.triangle_cache);
        node_cache.clear(threadIdx.x, blockDim.x);
        triangle_cache.clear(threadIdx.x, blockDim.x);
        __syncthreads();
        const CacheAddressMap map = cache_address_map(view, layout.nodes, layout.entries, layout.triangles);
        SharedCacheMemory<typename Traits::Node> mem(node_cache, triangle_cache, map, caches.async);
        fn(mem);
        add_counts(block_counts[2 * blockIdx.x], mem.node_counts);
        add_counts(block_counts[2 * blockIdx.x + 1], mem.triangle_counts);
    } else {
        DirectMemory<typename Traits::Node> mem = view.memory();
        fn(mem);
    }
}

template <class Traits, class Kernel, bool kAny, bool kShared>
__global__ void __launch_bounds__(kBlockThreads)
    trace_kernel(const std::byte* tree, PackedTree layout, const Ray* rays, Hit* hits, std::uint8_t* occluded,
                 std::uint32_t n, std::uint32_t* next, DeviceCounts* counts, SharedCaches caches,
                 DeviceCacheCounts* block_counts) {
    const TreeView<Traits> view = packed_view<Traits>(tree, layout);
    with_block_memory<Traits, kShared>(view, layout, caches, block_counts, [&](auto& mem) {
        trace_rays<Traits, Kernel, kAny>(view, mem, rays, hits, occluded, n, next, counts);
    });
}

// A persistent launch (the header's comment): sizes the grid for `kernel` (as many blocks as the device
// holds at once, at most `needed`), gives it scratch memory (the counts, `Counts`, zeroed; the warps'
// fetch counter; in mode (b) two cache counts a block) and calls launch(blocks, shared_bytes, counts,
// next, block_counts), which starts the kernel in `stream`. Returns the counts, read back when
// `want_counts` (waiting for the stream); in mode (b) adds the blocks' cache counts to `cache_stats`
// (waiting too). Each block has `memory`'s caches in its dynamic shared memory in mode (b).
template <bool kShared, class Counts, class KernelFn, class Launch>
Counts launch_persistent(KernelFn* kernel, std::uint32_t needed, int multiprocessors, cudaStream_t stream,
                         const DeviceMemoryConfig& memory, bool want_counts, DeviceCacheStats* cache_stats,
                         Launch&& launch) {
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
    const std::uint32_t resident = static_cast<std::uint32_t>(per_sm > 0 ? per_sm : 1) * multiprocessors;
    const std::uint32_t blocks = needed < resident ? needed : resident;
    const std::size_t kBlockCountsAt = align_up(sizeof(Counts) + sizeof(std::uint32_t), kPackedAlignment);
    const std::size_t block_count_bytes = kShared ? 2 * std::size_t(blocks) * sizeof(DeviceCacheCounts) : 0;
    StreamBuffer scratch(kBlockCountsAt + block_count_bytes, stream);
    auto* counts = scratch.at<Counts>(0);
    auto* block_counts = scratch.at<DeviceCacheCounts>(kBlockCountsAt);
    cuda_check(cudaMemsetAsync(counts, 0, kBlockCountsAt + block_count_bytes, stream), "cudaMemsetAsync");
    launch(blocks, shared_bytes, counts, scratch.at<std::uint32_t>(sizeof(Counts)), block_counts);
    cuda_check(cudaGetLastError(), "kernel launch");
    std::vector<DeviceCacheCounts> per_block(kShared ? 2 * std::size_t(blocks) : 0);
    if (kShared)
        cuda_check(cudaMemcpyAsync(per_block.data(), block_counts, block_count_bytes, cudaMemcpyDeviceToHost, stream),
                   "cudaMemcpyAsync (cache counts)");
    Counts sum{};
    if (want_counts)
        cuda_check(cudaMemcpyAsync(&sum, counts, sizeof sum, cudaMemcpyDeviceToHost, stream), "cudaMemcpyAsync");
    if (want_counts || kShared) cuda_check(cudaStreamSynchronize(stream), "kernel");
    if (kShared && cache_stats) {
        for (std::uint32_t b = 0; b < blocks; ++b) {
            cache_stats->node_cache += per_block[2 * b];
            cache_stats->triangle_cache += per_block[2 * b + 1];
        }
        cache_stats->blocks += blocks;
    }
    return sum;
}

// Launches the kernel over rays[0, n) in `stream` with a grid of persistent blocks, and adds the work
// counts to `counters` when non-null (waiting for the stream to read them). In mode (b) the blocks'
// cache counts are added to `cache_stats` (waiting for the stream).
template <class Traits, class Kernel, bool kAny, bool kShared>
void launch_trace(const std::byte* tree, const PackedTree& layout, const Ray* rays, Hit* hits, std::uint8_t* occluded,
                  std::uint32_t n, int multiprocessors, cudaStream_t stream, TraversalCounters* counters,
                  const DeviceMemoryConfig& memory, DeviceCacheStats* cache_stats) {
    if (n == 0) return;
    auto* kernel = &trace_kernel<Traits, Kernel, kAny, kShared>;
    const DeviceCounts sum = launch_persistent<kShared, DeviceCounts>(
        kernel, (n + kBlockThreads - 1) / kBlockThreads, multiprocessors, stream, memory, counters != nullptr,
        cache_stats,
        [&](std::uint32_t blocks, std::size_t shared_bytes, DeviceCounts* counts, std::uint32_t* next,
            DeviceCacheCounts* block_counts) {
            kernel<<<blocks, kBlockThreads, shared_bytes, stream>>>(
                tree, layout, rays, hits, occluded, n, next, counters ? counts : nullptr,
                SharedCaches{memory.node_cache, memory.triangle_cache, memory.async}, block_counts);
        });
    if (counters) {
        counters->rays += n;
        counters->nodes += sum.nodes;
        counters->leaves += sum.leaves;
        counters->triangles += sum.triangles;
    }
}

// The frame path (docs/GPU.md): each thread makes, traces and shades whole pixels (device_frame.hpp),
// a warp taking the next tile of 8 x 4 pixels of the window from one global counter, so that a warp's
// primary rays leave the camera side by side.
inline constexpr int kFrameTileWidth = 8, kFrameTileHeight = kWarp / kFrameTileWidth;

// A frame's sums: the primary rays' work, every other ray's, and those rays (64-bit: a frame's counts
// pass 2^32).
struct FrameCounts {
    DeviceCounts primary, secondary;
    unsigned long long secondary_rays;
};

template <class Traits, class Kernel, bool kShared>
__global__ void __launch_bounds__(kBlockThreads)
    frame_kernel(const std::byte* tree, PackedTree layout, const Triangle* triangles, FrameShading frame,
                 FrameWindow window, Vec3* pixels, std::uint32_t tiles, std::uint32_t* next, FrameCounts* counts,
                 SharedCaches caches, DeviceCacheCounts* block_counts) {
    const TreeView<Traits> view = packed_view<Traits>(tree, layout);
    with_block_memory<Traits, kShared>(view, layout, caches, block_counts, [&](auto& mem) {
        const unsigned lane = threadIdx.x % kWarp;
        const std::uint32_t tiles_x = (static_cast<std::uint32_t>(window.width) + kFrameTileWidth - 1) / kFrameTileWidth;
        PixelCounters c;
        for (;;) {
            std::uint32_t tile = 0;
            if (lane == 0) tile = atomicAdd(next, 1u);
            tile = __shfl_sync(0xffffffffu, tile, 0);
            if (tile >= tiles) break;
            const int x = static_cast<int>((tile % tiles_x) * kFrameTileWidth + lane % kFrameTileWidth);
            const int y = static_cast<int>((tile / tiles_x) * kFrameTileHeight + lane / kFrameTileWidth);
            if (x >= window.width || y >= window.height) continue;
            pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(window.width) + static_cast<std::size_t>(x)] =
                render_pixel<Traits, Kernel>(view, mem, frame, triangles, window.x0 + x, window.y0 + y, c);
        }
        add_counts(counts->primary, c.primary);
        add_counts(counts->secondary, c.secondary);
        atomicAdd(&counts->secondary_rays, static_cast<unsigned long long>(c.secondary_rays));
    });
}

// Renders `window` of the frame into pixels (device memory, window.width x window.height, row-major)
// in `stream`, waiting for it; adds the work counts to `primary` and `secondary` and returns the rays
// other than primary ones. Mode (b)'s cache counts go to `cache_stats`.
template <class Traits, class Kernel, bool kShared>
std::uint64_t launch_frame(const std::byte* tree, const PackedTree& layout, const Triangle* triangles,
                           const FrameShading& frame, const FrameWindow& window, Vec3* pixels, int multiprocessors,
                           cudaStream_t stream, const DeviceMemoryConfig& memory, TraversalCounters& primary,
                           TraversalCounters& secondary, DeviceCacheStats* cache_stats) {
    auto* kernel = &frame_kernel<Traits, Kernel, kShared>;
    const auto tiles = static_cast<std::uint32_t>(
        ((window.width + kFrameTileWidth - 1) / kFrameTileWidth) * ((window.height + kFrameTileHeight - 1) / kFrameTileHeight));
    constexpr std::uint32_t kTilesPerBlock = kBlockThreads / kWarp;
    const FrameCounts sum = launch_persistent<kShared, FrameCounts>(
        kernel, (tiles + kTilesPerBlock - 1) / kTilesPerBlock, multiprocessors, stream, memory, true, cache_stats,
        [&](std::uint32_t blocks, std::size_t shared_bytes, FrameCounts* counts, std::uint32_t* next,
            DeviceCacheCounts* block_counts) {
            kernel<<<blocks, kBlockThreads, shared_bytes, stream>>>(
                tree, layout, triangles, frame, window, pixels, tiles, next, counts,
                SharedCaches{memory.node_cache, memory.triangle_cache, memory.async}, block_counts);
        });
    const auto add = [](TraversalCounters& to, const DeviceCounts& c, std::uint64_t rays) {
        to.rays += rays;
        to.nodes += c.nodes;
        to.leaves += c.leaves;
        to.triangles += c.triangles;
    };
    add(primary, sum.primary, static_cast<std::uint64_t>(window.width) * static_cast<std::uint64_t>(window.height));
    add(secondary, sum.secondary, sum.secondary_rays);
    return sum.secondary_rays;
}

}  // namespace cellrt::detail
