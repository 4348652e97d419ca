// CUDA runtime calls checked: a failing call becomes a cellrt::Error naming the call and CUDA's own
// message. Device memory owned by RAII, allocated and freed in stream order.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <string>

#include "cellrt/device.hpp"
#include "cellrt/error.hpp"

namespace cellrt::detail {

// The device the backend runs on (device 0); throws cellrt::Error when there is none.
DeviceInfo require_cuda_device();

inline void cuda_check(cudaError_t status, const char* what) {
    if (status != cudaSuccess) throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
}

// `bytes` of device memory from the stream-ordered allocator, freed in the same stream.
class StreamBuffer {
public:
    StreamBuffer(std::size_t bytes, cudaStream_t stream) : stream_(stream) {
        cuda_check(cudaMallocAsync(&data_, bytes == 0 ? 1 : bytes, stream), "cudaMallocAsync");
    }
    ~StreamBuffer() { cudaFreeAsync(data_, stream_); }
    StreamBuffer(const StreamBuffer&) = delete;
    StreamBuffer& operator=(const StreamBuffer&) = delete;
    template <class T>
    T* at(std::size_t offset) const {
        return reinterpret_cast<T*>(static_cast<char*>(data_) + offset);
    }

private:
    void* data_ = nullptr;
    cudaStream_t stream_;
};

// A pair of events around a stream's work: the device's own time for it.
class StreamTimer {
public:
    explicit StreamTimer(cudaStream_t stream) : stream_(stream) {
        cuda_check(cudaEventCreate(&start_), "cudaEventCreate");
        cuda_check(cudaEventCreate(&stop_), "cudaEventCreate");
        cuda_check(cudaEventRecord(start_, stream), "cudaEventRecord");
    }
    ~StreamTimer() {
        cudaEventDestroy(start_);
        cudaEventDestroy(stop_);
    }
    StreamTimer(const StreamTimer&) = delete;
    StreamTimer& operator=(const StreamTimer&) = delete;
    // Waits for the work recorded since construction; its time in seconds.
    double seconds() {
        cuda_check(cudaEventRecord(stop_, stream_), "cudaEventRecord");
        cuda_check(cudaEventSynchronize(stop_), "cudaEventSynchronize");
        float ms = 0.f;
        cuda_check(cudaEventElapsedTime(&ms, start_, stop_), "cudaEventElapsedTime");
        return ms * 1e-3;
    }

private:
    cudaStream_t stream_;
    cudaEvent_t start_ = nullptr, stop_ = nullptr;
};

}  // namespace cellrt::detail
