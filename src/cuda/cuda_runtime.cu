// The CUDA runtime side of cellrt/device.hpp: which device is present, and resident ray batches.
#include <cuda_runtime.h>

#include "cellrt/device.hpp"
#include "cuda/cuda_check.cuh"

namespace cellrt {

DeviceInfo cuda_device_info() {
    DeviceInfo info;
    int count = 0;
    if (const cudaError_t e = cudaGetDeviceCount(&count); e != cudaSuccess) {
        info.reason = cudaGetErrorString(e);
        cudaGetLastError();  // clears the error so that later calls do not report it again
        return info;
    }
    if (count == 0) {
        info.reason = "no CUDA device";
        return info;
    }
    cudaDeviceProp p{};
    if (const cudaError_t e = cudaGetDeviceProperties(&p, 0); e != cudaSuccess) {
        info.reason = cudaGetErrorString(e);
        cudaGetLastError();  // as above: a later launch's check would report this error as its own
        return info;
    }
    info.present = true;
    info.name = p.name;
    info.compute_major = p.major;
    info.compute_minor = p.minor;
    info.multiprocessors = p.multiProcessorCount;
    info.memory_bytes = p.totalGlobalMem;
    info.shared_memory_per_block = p.sharedMemPerBlockOptin;
    return info;
}

DeviceRayBatch::DeviceRayBatch(std::size_t capacity) : capacity_(capacity) {
    detail::require_cuda_device();
    const std::size_t n = capacity == 0 ? 1 : capacity;
    try {
        detail::cuda_check(cudaMalloc(&rays_, n * sizeof(Ray)), "cudaMalloc (rays)");
        detail::cuda_check(cudaMalloc(&hits_, n * sizeof(Hit)), "cudaMalloc (hits)");
        detail::cuda_check(cudaMalloc(&occluded_, n), "cudaMalloc (occluded)");
    } catch (...) {
        cudaFree(rays_);
        cudaFree(hits_);
        cudaFree(occluded_);
        throw;
    }
}

DeviceRayBatch::~DeviceRayBatch() {
    cudaFree(rays_);
    cudaFree(hits_);
    cudaFree(occluded_);
}

void DeviceRayBatch::upload(std::span<const Ray> rays) {
    if (rays.size() > capacity_)
        throw Error("device batch: " + std::to_string(rays.size()) + " rays exceed its capacity of " +
                    std::to_string(capacity_));
    detail::cuda_check(cudaMemcpy(rays_, rays.data(), rays.size_bytes(), cudaMemcpyHostToDevice), "cudaMemcpy (rays)");
    size_ = rays.size();
}

void DeviceRayBatch::download_hits(std::span<Hit> hits) const {
    if (hits.size() != size_) throw Error("device batch: download of " + std::to_string(hits.size()) + " hits for " +
                                          std::to_string(size_) + " rays");
    detail::cuda_check(cudaMemcpy(hits.data(), hits_, hits.size_bytes(), cudaMemcpyDeviceToHost), "cudaMemcpy (hits)");
}

void DeviceRayBatch::download_occluded(std::span<std::uint8_t> occluded) const {
    if (occluded.size() != size_)
        throw Error("device batch: download of " + std::to_string(occluded.size()) + " answers for " +
                    std::to_string(size_) + " rays");
    detail::cuda_check(cudaMemcpy(occluded.data(), occluded_, occluded.size(), cudaMemcpyDeviceToHost),
                       "cudaMemcpy (occluded)");
}

namespace detail {

DeviceInfo require_cuda_device() {
    DeviceInfo info = cuda_device_info();
    if (!info.present) throw Error("device 'cuda': " + info.reason);
    return info;
}

}  // namespace detail
}  // namespace cellrt
