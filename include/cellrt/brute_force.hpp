// Brute force: every ray tests every triangle. The reference that all tests compare against.
#pragma once

#include <memory>
#include <span>

#include "cellrt/accelerator.hpp"

namespace cellrt {

// make_accelerator with kind "brute" (cellrt/accel.hpp), its checks included, on the CPU whatever
// config.kind and config.device say (its traversal, SIMD set and threads are read): `triangles` must
// outlive the accelerator, unchanged.
std::unique_ptr<Accelerator> make_brute_force(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt
