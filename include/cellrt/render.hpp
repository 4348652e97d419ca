// The renderer: one primary ray per pixel and the rays its shading casts from the hits (workload.hpp).
// `direct` is the study's: one shadow ray toward the point light, Lambert shading with a little ambient
// light. `ao` shades by the fraction of AO rays that escape; `diffuse` adds to the direct light one
// cosine-weighted bounce lit by the point light (or the sky where it escapes). Misses show the sky.
#pragma once

#include <atomic>
#include <functional>
#include <memory>

#include "cellrt/accel.hpp"
#include "cellrt/image.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/schedule.hpp"
#include "cellrt/shading.hpp"
#include "cellrt/workload.hpp"

namespace cellrt {

struct RenderOptions {
    int width = 512;
    int height = 512;
    unsigned threads = 0;  // worker threads; 0: all hardware threads
    int packet = 16;       // packet edge P in pixels: a P x P packet is one batch for the accelerator
    ShadingOptions shading;
    Dispatch dispatch = Dispatch::pull;  // how packets reach the workers (schedule.hpp)
    bool pin = false;      // pin worker threads to cores
    std::chrono::microseconds idle_spin = kDefaultIdleSpin;  // workers' poll before sleeping (schedule.hpp)
    bool count = false;    // collect traversal counters
    // Called now and then with (packets done, packets in all): from the worker threads, several at
    // once, under pull dispatch (from the master alone under mailbox), so it must be thread-safe; and
    // the counts may arrive out of order (the last call need not be the largest): keep the largest.
    std::function<void(std::size_t, std::size_t)> progress;
    // Set to true (for example from a signal handler) to stop early; render() then throws.
    const std::atomic<bool>* cancel = nullptr;
};

struct RenderStats {
    double seconds = 0.0;
    std::uint64_t primary_rays = 0;
    std::uint64_t secondary_rays = 0;      // every other ray: shadow, AO, bounce and bounce shadow rays
    TraversalCounters primary, secondary;  // filled when RenderOptions::count
    std::vector<WorkerLoad> workers;    // what each worker traced, and for how long
};

// Renders `scene` through `accel`, which must have been built over scene.triangles (shading reads the
// triangle a hit names). Throws cellrt::Error for a size check_image_size refuses, a bad camera, light
// (light_color_problem, a non-finite position), packet edge, worker count or AO sample count, when
// cancelled, or with the first exception a worker's packet threw (the other workers stop at their next
// packet). render() may be called from several threads; their frames are traced one after another
// (every frame runs on the process's one team of workers), and one called from inside a CPU frame
// (from `progress`) is refused.
// Given a device accelerator (cellrt/device.hpp) the frame is made on the device instead, one GPU
// thread a pixel (DeviceAccelerator::render_frame), with the same pixels bit for bit; the packet
// edge is still checked, the workers, dispatch and pinning play no part, progress is reported once,
// at the end, and device frames do not take the CPU frames' turns (nor are they refused inside one).
Image render(const Scene& scene, const Accelerator& accel, const RenderOptions& options,
             RenderStats* stats = nullptr);

// The same into `frame`, reusing its pixels when it already has the size (a renderer drawing frame
// after frame keeps its frame buffer; a fresh 512 x 512 buffer costs hundreds of page faults).
void render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, Image& frame,
            RenderStats* stats = nullptr);

// The pixels of `window` only, a rectangle inside the options.width x options.height frame, into
// `tile` (reused when it already has the window's size): each pixel gets the colour render() gives
// it, since a pixel's colour depends only on its own rays. Packets are cut from the window's top-left
// corner; `progress` counts the window's packets. Throws cellrt::Error as render() does, and for a
// window that is empty or not inside the frame.
void render_window(const Scene& scene, const Accelerator& accel, const RenderOptions& options, const PixelRect& window,
                   Image& tile, RenderStats* stats = nullptr);

// One frame traced window by window (a distributed frame, tile by tile): the camera and every
// worker's packet buffers are made once, so a frame cut into many windows costs no more set-up than
// one (with AO shading a workload's set-up reads every triangle for the rays' reach). Throws as render() does.
// One thread at a time may call render_window; scene, accel and options must outlive the renderer.
class FrameRenderer {
public:
    FrameRenderer(const Scene& scene, const Accelerator& accel, const RenderOptions& options);
    ~FrameRenderer();
    FrameRenderer(const FrameRenderer&) = delete;
    FrameRenderer& operator=(const FrameRenderer&) = delete;

    void render_window(const PixelRect& window, Image& tile, RenderStats* stats = nullptr);

private:
    struct State;
    void render_on_device(const PixelRect& window, Image& tile, RenderStats* stats);
    std::unique_ptr<State> state_;
};

}  // namespace cellrt
