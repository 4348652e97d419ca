// Intel Embree 3 as an accelerator: the yardstick that every cellrt benchmark measures against in the
// same run, on the same rays (docs/EMBREE.md). Compiled only where Embree 3 was found
// (CELLRT_HAVE_EMBREE).
//
// Build parameters (AccelConfig::params, validated by ParamReader):
//   quality = low | medium | high   Embree's RTC_BUILD_QUALITY_*: Morton build, SAH build, SAH build
//                                   with spatial splits. Default: medium (Embree's own default).
//   robust  = true | false          RTC_SCENE_FLAG_ROBUST: conservative box tests and Embree's
//                                   watertight Pluecker triangle test instead of Moeller-Trumbore; the
//                                   closest Embree comes to cellrt's hit rule. Default: true.
//   compact = true | false          RTC_SCENE_FLAG_COMPACT: triangles stored as vertex indices, less
//                                   memory, slower queries. Default: false.
// AccelConfig::threads: build threads (0: all hardware threads).
//
// Traversals (AccelConfig::traversal):
//   single    (default) rtcIntersect1 / rtcOccluded1 per ray
//   packet4, packet8, packet16   rtcIntersect4/8/16 and rtcOccluded4/8/16 over the batch in chunks; a
//             width is offered only where the CPU and the library run it natively (otherwise Embree
//             would emulate it, which is no yardstick), else make_embree throws.
#pragma once

#include "cellrt/accel.hpp"

namespace cellrt {

std::unique_ptr<Accelerator> make_embree(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt
