// `--accel auto`: cellrt's fastest exact path for a mix of coherent and incoherent batches. It holds
// two exact structures, SIMD packets over a study tree for coherent batches (a frame's primary rays,
// shadow rays toward one light) and the wide BVH for incoherent ones (diffuse bounces, AO, random
// queries), and routes each batch by its measured coherence (docs/BVH.md). Both return the brute-force
// hits, so the answers, and images, do not depend on the route.
#pragma once

#include <memory>
#include <span>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt::detail {

std::unique_ptr<Accelerator> make_routed(std::span<const Triangle> triangles, const AccelConfig& config);
const ParamTable& routed_params();
const std::vector<std::string>& routed_traversals();

// The batch's coherence: the mean cosine between the directions of neighbouring rays, over up to 64
// evenly spaced pairs (1 for parallel rays, about 0 for directions uniform on the sphere). Invalid
// rays are left out; a batch of fewer than two valid rays counts as coherent.
float batch_coherence(std::span<const Ray> rays);

}  // namespace cellrt::detail
