// The kd-tree behind the accelerator boundary (`--accel kd`).
#pragma once

#include "cellrt/accel.hpp"

namespace cellrt::detail {

std::unique_ptr<Accelerator> make_kdtree(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt::detail
