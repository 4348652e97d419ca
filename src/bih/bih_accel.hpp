// The BIH behind the accelerator boundary (`--accel bih`).
#pragma once

#include "cellrt/accel.hpp"

namespace cellrt::detail {

std::unique_ptr<Accelerator> make_bih(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt::detail
