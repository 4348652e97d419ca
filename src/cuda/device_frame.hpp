// What one thread of the GPU's frame path runs for one pixel, compiled for the host as well
// (CELLRT_HD) and tested there against the CPU renderer's image bit for bit
// (tests/test_device_code.cpp): the pixel's rays made, traced through the descriptor's kernel
// (device_trace.hpp) and shaded, all by shading.hpp's shade_pixel, as the CPU's frame workload makes
// and shades them.
#pragma once

#include <cstdint>

#include "cellrt/host_device.hpp"
#include "cellrt/shading.hpp"
#include "cuda/device_trace.hpp"

namespace cellrt::detail {

// The pixels [x0, x0 + width) x [y0, y0 + height) of a frame: a tile of a distributed frame, or the
// whole frame.
struct FrameWindow {
    int x0 = 0, y0 = 0, width = 0, height = 0;
};

// One thread's counts over its pixels: the work of primary and of every other ray, and those rays.
struct PixelCounters {
    RayCounters primary, secondary;
    std::uint32_t secondary_rays = 0;
};

// A ray of a pixel, traced: one call the pixel's program makes up to four times. Not inlined on the
// device, where four copies of a traversal in one kernel cost compile time and registers, not speed
// (the call's cost is small beside a traversal's).
template <class Traits, class Kernel, class Memory>
CELLRT_HD CELLRT_NOINLINE Hit pixel_closest(const TreeView<Traits>& view, Memory& mem, const Ray& ray, RayCounters& c) {
    return trace_closest<Traits, Kernel>(view, mem, ray, c);
}
template <class Traits, class Kernel, class Memory>
CELLRT_HD CELLRT_NOINLINE bool pixel_any(const TreeView<Traits>& view, Memory& mem, const Ray& ray, RayCounters& c) {
    return trace_any<Traits, Kernel>(view, mem, ray, c);
}

// The colour of pixel (x, y) of the frame `f`, its rays traced through `Kernel` over `view` in `mem`.
template <class Traits, class Kernel, class Memory>
CELLRT_HD Vec3 render_pixel(const TreeView<Traits>& view, Memory& mem, const FrameShading& f,
                            const Triangle* triangles, int x, int y, PixelCounters& c) {
    return shade_pixel(
        f, triangles, x, y,
        [&](const Ray& ray, bool primary) {
            if (primary) return pixel_closest<Traits, Kernel>(view, mem, ray, c.primary);
            ++c.secondary_rays;
            return pixel_closest<Traits, Kernel>(view, mem, ray, c.secondary);
        },
        [&](const Ray& ray) {
            ++c.secondary_rays;
            return pixel_any<Traits, Kernel>(view, mem, ray, c.secondary);
        });
}

}  // namespace cellrt::detail
