#include "cellrt/render.hpp"

#include <bit>
#include <cstring>

#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "core/timer.hpp"
#include "cellrt/workload.hpp"
#include "schedule/cache_line.hpp"

namespace cellrt {
namespace {

constexpr Vec3 kAlbedo{0.8f, 0.78f, 0.74f};
constexpr float kAmbient = 0.12f;

Vec3 sky(const Vec3& dir) {
    const float k = 0.5f * (dir.y + 1.f);
    return Vec3{0.9f, 0.95f, 1.f} * (1.f - k) + Vec3{0.35f, 0.55f, 0.9f} * k;
}

// One worker's packet rays and counters, made once per render and reused for every packet. On cache
// lines of their own: workers update their counters on every packet.
struct alignas(kCacheLine) PacketWork {
    PacketWorkload rays;
    TraversalCounters primary, secondary;
    std::uint64_t secondary_ray_count = 0;
};

// Lambert's cosine at the start of shadow ray k, 0 where something blocks the light.
float lambert(const RayBatch& shadow, std::size_t k) {
    return shadow.occluded[k] ? 0.f : std::max(0.f, dot(shadow.normals[k], shadow.rays[k].dir));
}

// The packet's shading from its rays (workload.hpp). Each pixel's colour is a sum in a fixed order
// of terms that hits decide, so it is the same bits under every structure.
void shade(const Scene& scene, const PacketWorkload& r, std::span<Vec3> colours) {
    const auto order = r.order();
    const RayBatch primary = r.batch(RayKind::primary);
    for (std::size_t i = 0; i < primary.rays.size(); ++i)
        if (!primary.hits[i].is_hit()) colours[order[i]] = sky(primary.rays[i].dir);
    switch (r.shading().shading) {
        case Shading::direct: {
            const RayBatch shadow = r.batch(RayKind::shadow);
            for (std::size_t k = 0; k < shadow.rays.size(); ++k)
                colours[order[shadow.parent[k]]] = kAlbedo * (kAmbient + lambert(shadow, k)) * scene.light.color;
            break;
        }
        case Shading::ao: {
            // The AO rays of a hit are consecutive: count those that escape, then shade once.
            const RayBatch ao = r.batch(RayKind::ao);
            const auto n = static_cast<std::size_t>(r.shading().ao_samples);
            for (std::size_t k = 0; k < ao.rays.size(); k += n) {
                std::size_t open = 0;
                for (std::size_t s = k; s < k + n; ++s) open += !ao.occluded[s];
                colours[order[ao.parent[k]]] = kAlbedo * (static_cast<float>(open) / static_cast<float>(n));
            }
            break;
        }
        case Shading::diffuse: {
            // With cosine-weighted bounces the estimate of the light a bounce brings is what arrives
            // along it (the cosine and the density cancel): the sky, or the direct light at its hit.
            const RayBatch shadow = r.batch(RayKind::shadow), bounce = r.batch(RayKind::bounce),
                           bounce_shadow = r.batch(RayKind::bounce_shadow);
            std::size_t m = 0;  // the next bounce shadow ray
            for (std::size_t k = 0; k < shadow.rays.size(); ++k) {
                Vec3 incoming = sky(bounce.rays[k].dir);
                if (bounce.hits[k].is_hit()) incoming = kAlbedo * scene.light.color * lambert(bounce_shadow, m++);
                colours[order[shadow.parent[k]]] = kAlbedo * (scene.light.color * lambert(shadow, k) + incoming);
            }
            break;
        }
    }
}

void trace_packet(const Scene& scene, const Accelerator& accel, const PixelRect& rect, bool count, PacketWork& w,
                  std::span<Vec3> colours) {
    w.rays.trace(rect, accel, count ? &w.primary : nullptr, count ? &w.secondary : nullptr);
    w.secondary_ray_count += w.rays.ray_count() - w.rays.batch(RayKind::primary).rays.size();
    shade(scene, w.rays, colours);
}

}  // namespace

SurfacePoint surface_point(const Triangle& tri, const Ray& ray, const Hit& hit) {
    Vec3 n = normalize(tri.geometric_normal());
    if (dot(n, ray.dir) > 0.f) n = -n;
    return {tri.v0 * (1.f - hit.u - hit.v) + tri.v1 * hit.u + tri.v2 * hit.v, n};
}

Vec3 offset_ray_origin(const Vec3& p, const Vec3& n) {
    // Far from the origin, move by a fixed number of ulps (integer offset on the float bits), which
    // scales with |p|; near the origin, where ulps are tiny, move by a small absolute amount.
    constexpr float kNearOrigin = 1.f / 32.f, kFloatScale = 1.f / 65536.f, kIntScale = 256.f;
    Vec3 out;
    for (int a = 0; a < 3; ++a) {
        const auto ulps = static_cast<std::int32_t>(kIntScale * n[a]);
        const std::int32_t bits = std::bit_cast<std::int32_t>(p[a]) + (p[a] < 0.f ? -ulps : ulps);
        out[a] = std::fabs(p[a]) < kNearOrigin ? p[a] + kFloatScale * n[a] : std::bit_cast<float>(bits);
    }
    return out;
}

Ray shadow_ray(const Vec3& p, const Vec3& n, const Vec3& light) {
    Ray s;
    s.org = offset_ray_origin(p, n);
    const Vec3 to_light = light - s.org;
    const float dist = length(to_light);
    s.dir = to_light * (1.f / dist);
    s.tnear = 0.f;
    s.tfar = dist * 0.9999f;  // stop just short of the light itself
    return s;
}

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
};

FrameRenderer::FrameRenderer(const Scene& scene, const Accelerator& accel, const RenderOptions& options)
    : state_(std::make_unique<State>(State{scene, accel, options, PinholeCamera(scene.camera, options.width,
                                                                                  options.height), {}, {}})) {
    ScheduleOptions& schedule = state_->schedule;
    schedule.dispatch = options.dispatch;
    schedule.workers = options.threads;
    schedule.pin = options.pin;
    schedule.idle_spin = options.idle_spin;
    schedule.cancel = options.cancel;
    schedule.progress = options.progress;
    static_cast<void>(PacketGrid(options.width, options.height, options.packet));  // refuses a bad packet edge
    // Sized here, so that workers never allocate: a thread's first allocation would create a malloc
    // arena of its own (page faults on every frame), and the hot path must not allocate.
    const auto packet_rays = static_cast<std::size_t>(options.packet) * static_cast<std::size_t>(options.packet);
    const unsigned workers = worker_count(schedule);
    state_->work.reserve(workers);
    for (unsigned w = 0; w < workers; ++w)
        state_->work.push_back({PacketWorkload(scene, state_->camera, packet_rays, options.shading)});
}

FrameRenderer::~FrameRenderer() = default;

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
    const PacketGrid grid(window.width(), window.height(), options.packet);
    if (image.width != window.width() || image.height != window.height())
        image = Image(window.width(), window.height());
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
