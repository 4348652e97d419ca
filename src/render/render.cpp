#include "cellrt/render.hpp"

#include <bit>
#include <cstring>

#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "cellrt/timer.hpp"
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
    TraversalCounters primary, shadow;
    std::uint64_t shadow_ray_count = 0;
};

// The packet's rays (workload.hpp), then its shading: sky for a miss, diffuse light where the shadow
// ray reaches the light, ambient light everywhere on a surface.
void trace_packet(const Scene& scene, const Accelerator& accel, const PixelRect& rect, bool count, PacketWork& w,
                  std::span<Vec3> colours) {
    PacketWorkload& r = w.rays;
    r.trace(rect, accel, count ? &w.primary : nullptr, count ? &w.shadow : nullptr);
    w.shadow_ray_count += r.shadow().size();
    const auto order = r.order();
    for (std::size_t i = 0; i < r.primary().size(); ++i)
        if (!r.hits()[i].is_hit()) colours[order[i]] = sky(r.primary()[i].dir);
    for (std::size_t k = 0; k < r.shadow().size(); ++k) {
        const float lambert = r.occluded()[k] ? 0.f : std::max(0.f, dot(r.normals()[k], r.shadow()[k].dir));
        colours[order[r.shadow_primary()[k]]] = kAlbedo * (kAmbient + lambert) * scene.light.color;
    }
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
    const PinholeCamera camera(scene.camera, options.width, options.height);
    const PacketGrid grid(options.width, options.height, options.packet);
    if (image.width != options.width || image.height != options.height) image = Image(options.width, options.height);
    ScheduleOptions schedule;
    schedule.dispatch = options.dispatch;
    schedule.workers = options.threads;
    schedule.pin = options.pin;
    schedule.idle_spin = options.idle_spin;
    schedule.cancel = options.cancel;
    schedule.progress = options.progress;
    // Sized here, so that workers never allocate: a thread's first allocation would create a malloc
    // arena of its own (page faults on every frame), and the hot path must not allocate.
    const auto packet_rays = static_cast<std::size_t>(options.packet) * static_cast<std::size_t>(options.packet);
    std::vector<PacketWork> work;
    work.reserve(worker_count(schedule));
    for (unsigned w = 0; w < worker_count(schedule); ++w) work.push_back({PacketWorkload(scene, camera, packet_rays)});

    Timer timer;
    std::vector<WorkerLoad> loads;
    const bool complete = run_packets(
        grid, schedule, image,
        [&](unsigned w, const PixelRect& rect, std::span<Vec3> out) {
            trace_packet(scene, accel, rect, options.count, work[w], out);
        },
        &loads);
    if (!complete) throw Error("render cancelled");
    if (stats) {
        *stats = RenderStats{};
        stats->seconds = timer.seconds();
        stats->primary_rays = static_cast<std::uint64_t>(options.width) * options.height;
        stats->workers = std::move(loads);
        for (const PacketWork& w : work) {
            stats->primary += w.primary;
            stats->shadow += w.shadow;
            stats->shadow_rays += w.shadow_ray_count;
        }
    }
}

}  // namespace cellrt
