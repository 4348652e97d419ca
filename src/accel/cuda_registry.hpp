// The CUDA backend of every tree the registry lists (structures.hpp), compiled by nvcc in
// cuda_registry.cu where CUDA was found.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/device.hpp"

namespace cellrt::detail {

using DeviceFactory = std::unique_ptr<DeviceAccelerator> (*)(std::span<const Triangle>, const AccelConfig&);

struct DeviceEntry {
    const char* kind;
    DeviceFactory make;
};

// One entry per listed tree, in list order.
std::vector<DeviceEntry> cuda_factories();

}  // namespace cellrt::detail
