// The wide BVH as an accelerator (docs/BVH.md): cellrt's structure for rays that do not come in
// coherent packets (AO, diffuse bounces, random queries), one ray at a time with eight-wide SIMD over
// a node's children and a leaf's triangles. Exact under the hit rule, like the trees.
//
// Build parameters: bvh_params(). The build runs on AccelConfig::threads (its subtrees as oneTBB
// tasks; the same tree at any count). Traversals: "paired" (single rays, two walks at a time,
// bvh_kernels.inl; the default), "wide" (single rays, one walk), "stream" (the batch's rays down the tree
// together, bvh_stream.inl: each node read once per stream) and "packet" (eight consecutive rays of
// the batch together, sixteen with AVX-512, one per lane, bvh_packet.inl). The kernels come from the
// registry, compiled for the instruction set AccelConfig::simd names (registry: bvh_kernels_for;
// nodes and leaves in eight lanes in every set).
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

namespace detail {
// The tree of `bvh` (an accelerator make_bvh made) traced by `traversal`, without a second build:
// the view reads `bvh`'s tree, so `bvh` must outlive it. Throws cellrt::Error for another kind of
// accelerator or an unknown traversal. (The router's paths share one tree: routed_accelerator.cpp.)
std::unique_ptr<Accelerator> bvh_with_traversal(const Accelerator& bvh, const std::string& traversal);
}  // namespace detail
const std::vector<std::string>& bvh_traversals();

}  // namespace cellrt
