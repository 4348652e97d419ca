#include "cellrt/render.hpp"

#include <bit>
#include <cstring>

#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "cellrt/timer.hpp"
#include "schedule/cache_line.hpp"

namespace cellrt {
namespace {

constexpr Vec3 kAlbedo{0.8f, 0.78f, 0.74f};
constexpr float kAmbient = 0.12f;

Vec3 sky(const Vec3& dir) {
    const float k = 0.5f * (dir.y + 1.f);
    return Vec3{0.9f, 0.95f, 1.f} * (1.f - k) + Vec3{0.35f, 0.55f, 0.9f} * k;
}

// Buffers of one worker, allocated once per render, reused for every packet. On cache lines of their
// own: workers update their vectors' ends and counters and write the buffers on every packet.
struct alignas(kCacheLine) PacketWork {
    CacheLineVector<Ray> rays, shadow_rays;
    CacheLineVector<Hit> hits;
    CacheLineVector<std::uint8_t> occluded;
    CacheLineVector<Vec3> normals;
    CacheLineVector<std::uint32_t> shadow_pixel;
    CacheLineVector<std::uint32_t> order;  // order[i]: the pixel (offset in the packet) of ray i
    int order_width = 0, order_height = 0;  // the packet shape `order` was made for
    TraversalCounters primary, shadow;
    std::uint64_t shadow_ray_count = 0;

    void reserve(std::size_t n) {
        rays.reserve(n);
        shadow_rays.reserve(n);
        hits.reserve(n);
        occluded.reserve(n);
        normals.reserve(n);
        shadow_pixel.reserve(n);
        order.reserve(n);
    }
};

// Primary rays of the packet, one batch; then one shadow ray per hit, one batch; then shading.
void trace_packet(const Scene& scene, const Accelerator& accel, const PinholeCamera& camera, const PixelRect& rect,
                  bool count, PacketWork& w, std::span<Vec3> colours) {
    if (rect.width() != w.order_width || rect.height() != w.order_height) {  // only edge packets differ
        w.order.resize(static_cast<std::size_t>(rect.pixels()));
        packet_order(rect, w.order);
        w.order_width = rect.width();
        w.order_height = rect.height();
    }
    w.rays.clear();
    for (const std::uint32_t p : w.order)
        w.rays.push_back(camera.primary(rect.x0 + static_cast<int>(p) % rect.width(), rect.y0 + static_cast<int>(p) / rect.width()));
    w.hits.resize(w.rays.size());
    accel.intersect(w.rays, w.hits, count ? &w.primary : nullptr);

    w.shadow_rays.clear();
    w.shadow_pixel.clear();
    w.normals.resize(w.rays.size());
    for (std::size_t i = 0; i < w.rays.size(); ++i) {
        const Hit& h = w.hits[i];
        if (!h.is_hit()) {
            colours[w.order[i]] = sky(w.rays[i].dir);
            continue;
        }
        const SurfacePoint sp = surface_point(scene.triangles[h.prim], w.rays[i], h);
        w.normals[i] = sp.normal;
        w.shadow_rays.push_back(shadow_ray(sp.position, sp.normal, scene.light.position));
        w.shadow_pixel.push_back(static_cast<std::uint32_t>(i));
    }
    w.shadow_ray_count += w.shadow_rays.size();
    w.occluded.resize(w.shadow_rays.size());
    accel.occluded(w.shadow_rays, w.occluded, count ? &w.shadow : nullptr);

    for (std::size_t k = 0; k < w.shadow_rays.size(); ++k) {
        const std::uint32_t i = w.shadow_pixel[k];
        const float lambert = w.occluded[k] ? 0.f : std::max(0.f, dot(w.normals[i], w.shadow_rays[k].dir));
        colours[w.order[i]] = kAlbedo * (kAmbient + lambert) * scene.light.color;
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
    std::vector<PacketWork> work(worker_count(schedule));
    // Sized here, so that workers never allocate: a thread's first allocation would create a malloc
    // arena of its own (page faults on every frame), and the hot path must not allocate.
    const auto packet_rays = static_cast<std::size_t>(options.packet) * static_cast<std::size_t>(options.packet);
    for (PacketWork& w : work) w.reserve(packet_rays);

    Timer timer;
    std::vector<WorkerLoad> loads;
    const bool complete = run_packets(
        grid, schedule, image,
        [&](unsigned w, const PixelRect& rect, std::span<Vec3> out) {
            trace_packet(scene, accel, camera, rect, options.count, work[w], out);
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
