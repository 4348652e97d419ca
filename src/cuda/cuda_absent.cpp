// cellrt/device.hpp in a build without CUDA (nvcc absent, or CELLRT_CUDA=OFF): no device, and every
// attempt to use one refused with that reason.
#ifndef CELLRT_HAVE_CUDA
#include "cellrt/device.hpp"
#include "cellrt/error.hpp"

namespace cellrt {
namespace {
constexpr const char* kAbsent = "this cellrt was built without CUDA: no nvcc, or CELLRT_CUDA=OFF, when it was configured";
}

DeviceInfo cuda_device_info() {
    DeviceInfo info;
    info.reason = kAbsent;
    return info;
}

DeviceRayBatch::DeviceRayBatch(std::size_t) { throw Error(std::string("device 'cuda': ") + kAbsent); }
DeviceRayBatch::~DeviceRayBatch() = default;
void DeviceRayBatch::upload(std::span<const Ray>) { throw Error(std::string("device 'cuda': ") + kAbsent); }
void DeviceRayBatch::download_hits(std::span<Hit>) const { throw Error(std::string("device 'cuda': ") + kAbsent); }
void DeviceRayBatch::download_occluded(std::span<std::uint8_t>) const {
    throw Error(std::string("device 'cuda': ") + kAbsent);
}

}  // namespace cellrt
#endif
