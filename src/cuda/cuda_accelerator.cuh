// A tree on the GPU behind the accelerator boundary: built on the host by its descriptor `S` (the same
// tree the CPU paths trace), packed (device_tree.hpp) and copied to the device once; traced there by
// the descriptor's own kernels, one ray per thread (trace_kernels.cuh), in the memory mode its -P
// parameters choose (device_memory.hpp: the tree in global memory, or the study's software caches in
// shared memory). Host batches are copied in and
// out in the calling thread's own stream, so calls from many threads run at once, as the boundary
// requires (accelerator.hpp).
#pragma once

#include <cuda_runtime.h>

#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

#include "cellrt/device.hpp"
#include "core/timer.hpp"
#include "cuda/cuda_check.cuh"
#include "cuda/device_memory.hpp"
#include "cuda/trace_kernels.cuh"
#include "kernel/named.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt::detail {

template <class S>
class CudaAccelerator final : public DeviceAccelerator {
public:
    CudaAccelerator(std::span<const Triangle> triangles, const AccelConfig& config)
        : traversal_name_(choose_traversal(names_of(S::kTraversals), config.traversal, S::kName)),
          traversal_(value_named(S::kTraversals, traversal_name_, "traversal")),
          memory_(read_device_memory(config)),
          device_(require_cuda_device()),
          scene_triangles_(triangles.size()) {
        Timer timer;
        const S s(triangles, without_device_memory(config));
        stats_.build_seconds = timer.seconds();
        stats_.name = S::kName;
        stats_.traversal = traversal_name_;
        stats_.memory_bytes = s.memory_bytes();
        stats_.triangles = s.triangle_array().size();
        stats_.tree = s.report();
        stats_.settings = s.settings();
        stats_.settings.push_back({"device", "cuda: " + device_.name});
        stats_.settings.push_back({"memory", memory_.to_string()});
        layout_ = packed_layout<typename S::Traits>(s.nodes().size(), s.entries().size(), s.triangle_array().size(),
                                                   s.bounds());
        check_shared_memory(memory_, device_.shared_memory_per_block,
                            cache_address_map(TreeView<typename S::Traits>{}, layout_.nodes, layout_.entries,
                                              layout_.triangles)
                                .end);
        std::vector<std::byte> host(layout_.bytes);
        pack_tree<typename S::Traits>(s.nodes(), s.entries(), s.triangle_array(), layout_, host.data());
        cuda_check(cudaMalloc(&tree_, layout_.bytes), "cudaMalloc (tree)");
        if (const cudaError_t e = cudaMemcpy(tree_, host.data(), layout_.bytes, cudaMemcpyHostToDevice); e != cudaSuccess) {
            cudaFree(tree_);
            cuda_check(e, "cudaMemcpy (tree)");
        }
    }
    ~CudaAccelerator() override { cudaFree(tree_); }
    CudaAccelerator(const CudaAccelerator&) = delete;
    CudaAccelerator& operator=(const CudaAccelerator&) = delete;

    AccelStats stats() const override { return stats_; }
    DeviceCacheStats cache_stats() const override {
        const std::lock_guard lock(cache_mutex_);
        return cache_stats_;
    }

    double intersect_resident(DeviceRayBatch& batch, TraversalCounters* counters) const override {
        StreamTimer timer(cudaStreamPerThread);
        launch<false>(batch.device_rays(), batch.device_hits(), nullptr, batch.size(), cudaStreamPerThread, counters);
        return timer.seconds();
    }
    double occluded_resident(DeviceRayBatch& batch, TraversalCounters* counters) const override {
        StreamTimer timer(cudaStreamPerThread);
        launch<true>(batch.device_rays(), nullptr, batch.device_occluded(), batch.size(), cudaStreamPerThread,
                     counters);
        return timer.seconds();
    }

    FrameResult render_frame(std::span<const Triangle> triangles, const FrameShading& frame, int x0, int y0, int width,
                             int height, std::span<Vec3> pixels, TraversalCounters& primary,
                             TraversalCounters& secondary) const override {
        const auto window = [&] {
            return std::to_string(width) + "x" + std::to_string(height) + " at (" + std::to_string(x0) + ", " +
                   std::to_string(y0) + ")";
        };
        if (width < 1 || height < 1) throw Error("device frame: the window " + window() + " is empty");
        const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
        if (pixels.size() != n)
            throw Error("device frame: " + std::to_string(pixels.size()) + " pixels given for the window " + window());
        if (triangles.size() != scene_triangles_)
            throw Error("device frame: " + std::to_string(triangles.size()) + " triangles given for a tree built over " +
                        std::to_string(scene_triangles_));
        Timer wall;
        const cudaStream_t stream = cudaStreamPerThread;
        const std::size_t pixels_at = align_up(triangles.size_bytes(), kPackedAlignment);
        StreamBuffer buffer(pixels_at + pixels.size_bytes(), stream);
        if (!triangles.empty())
            cuda_check(cudaMemcpyAsync(buffer.at<Triangle>(0), triangles.data(), triangles.size_bytes(),
                                       cudaMemcpyHostToDevice, stream),
                       "cudaMemcpyAsync (triangles)");
        FrameResult result;
        StreamTimer timer(stream);
        dispatch([&](auto kernel, auto shared, DeviceCacheStats& cache) {
            launch_frame<typename S::Traits, decltype(kernel), decltype(shared)::value>(
                static_cast<const std::byte*>(tree_), layout_, buffer.at<Triangle>(0), frame,
                FrameWindow{x0, y0, width, height}, buffer.at<Vec3>(pixels_at), device_.multiprocessors, stream, memory_,
                primary, secondary, &cache);
        });
        result.kernel_seconds = timer.seconds();
        cuda_check(cudaMemcpyAsync(pixels.data(), buffer.at<Vec3>(pixels_at), pixels.size_bytes(),
                                   cudaMemcpyDeviceToHost, stream),
                   "cudaMemcpyAsync (pixels)");
        cuda_check(cudaStreamSynchronize(stream), "frame");
        result.seconds = wall.seconds();
        return result;
    }

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        host_batch<false>(rays, hits.data(), hits.size_bytes(), counters);
    }
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        host_batch<true>(rays, occluded.data(), occluded.size_bytes(), counters);
    }

    // Rays in, kernel, answers out, in this thread's stream; returns when the answers are in `out`.
    template <bool kAny>
    void host_batch(std::span<const Ray> rays, void* out, std::size_t out_bytes, TraversalCounters* counters) const {
        if (rays.empty()) return;
        const cudaStream_t stream = cudaStreamPerThread;
        const std::size_t out_offset = align_up(rays.size_bytes(), kPackedAlignment);
        StreamBuffer buffer(out_offset + out_bytes, stream);
        cuda_check(cudaMemcpyAsync(buffer.at<Ray>(0), rays.data(), rays.size_bytes(), cudaMemcpyHostToDevice, stream),
                   "cudaMemcpyAsync (rays)");
        launch<kAny>(buffer.at<Ray>(0), buffer.at<Hit>(out_offset), buffer.at<std::uint8_t>(out_offset), rays.size(),
                     stream, counters);
        cuda_check(cudaMemcpyAsync(out, buffer.at<char>(out_offset), out_bytes, cudaMemcpyDeviceToHost, stream),
                   "cudaMemcpyAsync (answers)");
        cuda_check(cudaStreamSynchronize(stream), "kernel");
    }

    template <bool kAny>
    void launch(const Ray* rays, Hit* hits, std::uint8_t* occluded, std::size_t n, cudaStream_t stream,
                TraversalCounters* counters) const {
        // The warps' fetch counter runs up to n plus 32 a warp, in 32 bits.
        if (n > (std::size_t{1} << 31)) throw Error("a device batch holds at most 2^31 rays");
        dispatch([&](auto kernel, auto shared, DeviceCacheStats& cache) {
            launch_trace<typename S::Traits, decltype(kernel), kAny, decltype(shared)::value>(
                static_cast<const std::byte*>(tree_), layout_, rays, hits, occluded, static_cast<std::uint32_t>(n),
                device_.multiprocessors, stream, counters, memory_, &cache);
        });
    }

    // Calls go(kernel, std::bool_constant<shared>, cache) with the chosen traversal's kernel and memory
    // mode, then adds the launch's cache counts (mode (b)) to the accelerator's.
    template <class Go>
    void dispatch(Go&& go) const {
        DeviceCacheStats cache;
        S::with_kernel(traversal_, [&](auto kernel) {
            if (memory_.shared) go(kernel, std::true_type{}, cache);
            else go(kernel, std::false_type{}, cache);
        });
        if (memory_.shared) {
            const std::lock_guard lock(cache_mutex_);
            cache_stats_.node_cache += cache.node_cache;
            cache_stats_.triangle_cache += cache.triangle_cache;
            cache_stats_.blocks += cache.blocks;
        }
    }

    std::string traversal_name_;
    typename S::Traversal traversal_;
    DeviceMemoryConfig memory_;
    DeviceInfo device_;
    std::size_t scene_triangles_;  // the triangles the tree was built over: a frame's hits name them
    AccelStats stats_;
    PackedTree layout_;
    void* tree_ = nullptr;
    mutable std::mutex cache_mutex_;
    mutable DeviceCacheStats cache_stats_;
};

}  // namespace cellrt::detail
