// Intel Embree 3 as an accelerator: the yardstick that every cellrt benchmark measures against in the
// same run, on the same rays (docs/EMBREE.md). Compiled only where Embree 3 was found
// (CELLRT_HAVE_EMBREE).
//
// Build parameters: embree_params() (quality, robust, compact). AccelConfig::threads: build threads
// (0: all hardware threads).
//
// Traversals (AccelConfig::traversal):
//   single    (default) rtcIntersect1 / rtcOccluded1 per ray
//   packet4, packet8, packet16   rtcIntersect4/8/16 and rtcOccluded4/8/16 over the batch in chunks; a
//             width is offered only where the CPU and the library run it natively (otherwise Embree
//             would emulate it, which is no yardstick), else make_embree throws.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt {

std::unique_ptr<Accelerator> make_embree(std::span<const Triangle> triangles, const AccelConfig& config);
const ParamTable& embree_params();
const std::vector<std::string>& embree_traversals();

}  // namespace cellrt
