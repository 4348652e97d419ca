#include "cellrt/render.hpp"

#include <cstring>

#include "cellrt/camera.hpp"
#include "cellrt/device.hpp"
#include "cellrt/error.hpp"
#include "core/timer.hpp"
#include "cellrt/workload.hpp"
#include "schedule/cache_line.hpp"

namespace cellrt {
namespace {

// One worker's packet rays and counters, made once per render and reused for every packet. On cache
// lines of their own: workers update their counters on every packet.
struct alignas(kCacheLine) PacketWork {
    PacketWorkload rays;
    TraversalCounters primary, secondary;
    std::uint64_t secondary_ray_count = 0;
};

// Lambert's cosine at the start of shadow ray k, 0 where something blocks the light.
float lambert(const RayBatch& shadow, std::size_t k) {
    return shade::lambert(shadow.occluded[k] != 0, shadow.normals[k], shadow.rays[k].dir);
}

// The packet's shading from its rays (workload.hpp), with the colours of shading.hpp: those the GPU's
// frame path gives each pixel (shade_pixel).
void shade_packet(const Scene& scene, const PacketWorkload& r, std::span<Vec3> colours) {
    const auto order = r.order();
    const RayBatch primary = r.batch(RayKind::primary);
    for (std::size_t i = 0; i < primary.rays.size(); ++i)
        if (!primary.hits[i].is_hit()) colours[order[i]] = shade::sky(primary.rays[i].dir);
    switch (r.shading().shading) {
        case Shading::direct: {
            const RayBatch shadow = r.batch(RayKind::shadow);
            for (std::size_t k = 0; k < shadow.rays.size(); ++k)
                colours[order[shadow.parent[k]]] = shade::direct(lambert(shadow, k), scene.light.color);
            break;
        }
        case Shading::ao: {
            // The AO rays of a hit are consecutive: count those that escape, then shade once.
            const RayBatch ao = r.batch(RayKind::ao);
            const int n = r.shading().ao_samples;
            for (std::size_t k = 0; k < ao.rays.size(); k += static_cast<std::size_t>(n)) {
                int open = 0;
                for (std::size_t s = k; s < k + static_cast<std::size_t>(n); ++s) open += ao.occluded[s] ? 0 : 1;
                colours[order[ao.parent[k]]] = shade::ambient_occlusion(open, n);
            }
            break;
        }
        case Shading::diffuse: {
            const RayBatch shadow = r.batch(RayKind::shadow), bounce = r.batch(RayKind::bounce),
                           bounce_shadow = r.batch(RayKind::bounce_shadow);
            std::size_t m = 0;  // the next bounce shadow ray
            for (std::size_t k = 0; k < shadow.rays.size(); ++k) {
                Vec3 incoming = shade::sky(bounce.rays[k].dir);
                if (bounce.hits[k].is_hit()) incoming = shade::bounce_light(lambert(bounce_shadow, m++), scene.light.color);
                colours[order[shadow.parent[k]]] = shade::diffuse(lambert(shadow, k), scene.light.color, incoming);
            }
            break;
        }
    }
}

void trace_packet(const Scene& scene, const Accelerator& accel, const PixelRect& rect, bool count, PacketWork& w,
                  std::span<Vec3> colours) {
    w.rays.trace(rect, accel, count ? &w.primary : nullptr, count ? &w.secondary : nullptr);
    w.secondary_ray_count += w.rays.ray_count() - w.rays.batch(RayKind::primary).rays.size();
    shade_packet(scene, w.rays, colours);
}

}  // namespace

Image render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, RenderStats* stats) {
    Image image;
    render(scene, accel, options, image, stats);
    return image;
}

void render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, Image& image,
            RenderStats* stats) {
    render_window(scene, accel, options, PixelRect{0, 0, options.width, options.height}, image, stats);
}

void render_window(const Scene& scene, const Accelerator& accel, const RenderOptions& options, const PixelRect& window,
                   Image& image, RenderStats* stats) {
    FrameRenderer(scene, accel, options).render_window(window, image, stats);
}

struct FrameRenderer::State {
    const Scene& scene;
    const Accelerator& accel;
    const RenderOptions& options;
    PinholeCamera camera;
    ScheduleOptions schedule;
    std::vector<PacketWork> work;
    // A device accelerator renders on the device (the GPU's frame path).
    const DeviceAccelerator* device = nullptr;
    FrameShading frame;  // what the frame's rays and colours need: the device's threads, the workers
};

FrameRenderer::FrameRenderer(const Scene& scene, const Accelerator& accel, const RenderOptions& options)
    : state_(std::make_unique<State>(State{scene, accel, options, PinholeCamera(scene.camera, options.width,
                                                                                  options.height), {}, {}})) {
    // The light as validate_scene checks it (a Scene made in code need not have passed there): a NaN
    // or negative colour shaded NaN or negative pixels, a NaN position no light at all (found by
    // audit, 2026-12-07).
    if (!is_finite(scene.light.position)) throw Error("the light position is not finite");
    if (const std::string why = light_color_problem(scene.light.color); !why.empty()) throw Error(why);
    ScheduleOptions& schedule = state_->schedule;
    schedule.dispatch = options.dispatch;
    schedule.workers = options.threads;
    schedule.pin = options.pin;
    schedule.idle_spin = options.idle_spin;
    schedule.cancel = options.cancel;
    schedule.progress = options.progress;
    static_cast<void>(PacketGrid(options.width, options.height, options.packet));  // refuses a bad packet edge
    state_->device = dynamic_cast<const DeviceAccelerator*>(&accel);
    // Made once for every worker: for AO it reads every triangle (the rays' reach), 0.27 ms on Sponza,
    // which once per worker was 4 ms of one thread's time before a 16-thread frame.
    state_->frame = frame_shading(scene, state_->camera, options.shading);
    if (state_->device) return;
    // Sized here, so that workers never allocate: a thread's first allocation would create a malloc
    // arena of its own (page faults on every frame), and the hot path must not allocate.
    const auto packet_rays = static_cast<std::size_t>(options.packet) * static_cast<std::size_t>(options.packet);
    const unsigned workers = worker_count(schedule);
    state_->work.reserve(workers);
    for (unsigned w = 0; w < workers; ++w) state_->work.push_back({PacketWorkload(scene, state_->frame, packet_rays)});
}

FrameRenderer::~FrameRenderer() = default;

// The frame path of a device accelerator: every pixel of the window made, traced and shaded on the
// device, one thread a pixel, with the colours the packets below give (shading.hpp's shade_pixel).
void FrameRenderer::render_on_device(const PixelRect& window, Image& image, RenderStats* stats) {
    const State& s = *state_;
    const RenderOptions& options = s.options;
    if (options.cancel && options.cancel->load()) throw Error("render cancelled");
    TraversalCounters primary, secondary;
    Timer timer;
    s.device->render_frame(s.scene.triangles, s.frame, window.x0, window.y0, window.width(), window.height(),
                           image.pixels, primary, secondary);
    if (options.progress) options.progress(1, 1);
    if (stats) {
        *stats = RenderStats{};
        stats->seconds = timer.seconds();
        stats->primary_rays = static_cast<std::uint64_t>(window.pixels());
        stats->secondary_rays = secondary.rays;
        if (options.count) {
            stats->primary = primary;
            stats->secondary = secondary;
        }
    }
}

void FrameRenderer::render_window(const PixelRect& window, Image& image, RenderStats* stats) {
    const Scene& scene = state_->scene;
    const Accelerator& accel = state_->accel;
    const RenderOptions& options = state_->options;
    std::vector<PacketWork>& work = state_->work;
    if (window.x0 < 0 || window.y0 < 0 || window.x1 > options.width || window.y1 > options.height ||
        window.width() < 1 || window.height() < 1)
        throw Error("window [" + std::to_string(window.x0) + ", " + std::to_string(window.x1) + ") x [" +
                    std::to_string(window.y0) + ", " + std::to_string(window.y1) + ") is not inside the " +
                    std::to_string(options.width) + "x" + std::to_string(options.height) + " frame");
    // Its pixels too: a moved-from Image keeps its sides and holds none.
    if (image.width != window.width() || image.height != window.height() ||
        image.pixels.size() != static_cast<std::size_t>(window.pixels()))
        image = Image(window.width(), window.height());
    if (state_->device) {
        render_on_device(window, image, stats);
        return;
    }
    const PacketGrid grid(window.width(), window.height(), options.packet);
    for (PacketWork& w : work) {
        w.primary = w.secondary = TraversalCounters{};
        w.secondary_ray_count = 0;
    }

    Timer timer;
    std::vector<WorkerLoad> loads;
    // The grid's packets are the window's; the rays are the frame's pixels under them.
    const bool complete = run_packets(
        grid, state_->schedule, image,
        [&](unsigned w, const PixelRect& rect, std::span<Vec3> out) {
            const PixelRect pixels{rect.x0 + window.x0, rect.y0 + window.y0, rect.x1 + window.x0, rect.y1 + window.y0};
            trace_packet(scene, accel, pixels, options.count, work[w], out);
        },
        &loads);
    if (!complete) throw Error("render cancelled");
    if (stats) {
        *stats = RenderStats{};
        stats->seconds = timer.seconds();
        stats->primary_rays = static_cast<std::uint64_t>(window.pixels());
        stats->workers = std::move(loads);
        for (const PacketWork& w : work) {
            stats->primary += w.primary;
            stats->secondary += w.secondary;
            stats->secondary_rays += w.secondary_ray_count;
        }
    }
}

}  // namespace cellrt
