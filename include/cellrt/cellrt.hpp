// The whole public C++ API in one header: scenes and their loaders, the accelerators and their
// configuration, the frame workload and the renderer, the scheduler, and the version. The C API is
// cellrt.h. Each header states its own thread safety and lifetimes.
#pragma once

#include "cellrt/accel.hpp"
#include "cellrt/accelerator.hpp"
#include "cellrt/box.hpp"
#include "cellrt/brute_force.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/device.hpp"
#include "cellrt/error.hpp"
#include "cellrt/image.hpp"
#include "cellrt/loaders.hpp"
#include "cellrt/params.hpp"
#include "cellrt/ray.hpp"
#include "cellrt/render.hpp"
#include "cellrt/sampling.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/schedule.hpp"
#include "cellrt/triangle.hpp"
#include "cellrt/vec.hpp"
#include "cellrt/version.hpp"
#include "cellrt/workload.hpp"
