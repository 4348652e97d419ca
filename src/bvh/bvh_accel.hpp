// The wide BVH as an accelerator (docs/BVH.md): cellrt's structure for rays that do not come in
// coherent packets (AO, diffuse bounces, random queries), one ray at a time with eight-wide SIMD over
// a node's children and a leaf's triangles. Exact under the hit rule, like the trees.
//
// Build parameters: bvh_params(). The build runs on one thread (AccelConfig::threads is not used).
// Traversals: "wide" (the one). The kernels come from the registry, compiled for the instruction set
// AccelConfig::simd names (registry: bvh_kernels_for; eight lanes in every set).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bvh/bvh_kernels.hpp"
#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt {

std::unique_ptr<Accelerator> make_bvh(std::span<const Triangle> triangles, const AccelConfig& config,
                                      const detail::BvhKernels& kernels);
const ParamTable& bvh_params();
const std::vector<std::string>& bvh_traversals();

}  // namespace cellrt
