// The CUDA backend instantiated for every tree of the one list (structures.hpp): each tree's kernels
// (every traversal, closest and any hit) compiled for the device from the host's own source.
#include "accel/cuda_registry.hpp"

#include <type_traits>

#include "accel/structures.hpp"
#include "cuda/cuda_accelerator.cuh"

namespace cellrt::detail {
namespace {

template <class S>
std::unique_ptr<DeviceAccelerator> make_cuda(std::span<const Triangle> triangles, const AccelConfig& config) {
    return std::make_unique<CudaAccelerator<S>>(triangles, config);
}

}  // namespace

std::vector<DeviceEntry> cuda_factories() {
    std::vector<DeviceEntry> out;
    TreeStructures::for_each([&]<class S>(std::type_identity<S>) { out.push_back({S::kName, &make_cuda<S>}); });
    return out;
}

}  // namespace cellrt::detail
