// The wide BVH as an accelerator (docs/BVH.md): cellrt's structure for rays that do not come in
// coherent packets (AO, diffuse bounces, random queries), one ray at a time with eight-wide SIMD over
// a node's children and a leaf's triangles. Exact under the hit rule, like the trees.
//
// Build parameters: bvh_params(). The build runs on one thread (AccelConfig::threads is not used).
// Traversals: "wide" (the one). AccelConfig::simd picks the kernels' instruction set: "off" and
// "auto" the best this processor runs, "portable" or "sse" the generic ones, "avx2" or "avx512"
// those (eight lanes in both; AVX-512 adds registers).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt {

std::unique_ptr<Accelerator> make_bvh(std::span<const Triangle> triangles, const AccelConfig& config);
const ParamTable& bvh_params();
const std::vector<std::string>& bvh_traversals();

}  // namespace cellrt
