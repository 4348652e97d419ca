#include "cellrt/render.hpp"

#include <bit>
#include <cstring>
#include <mutex>
#include <thread>

#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "cellrt/timer.hpp"

namespace cellrt {
namespace {

constexpr Vec3 kAlbedo{0.8f, 0.78f, 0.74f};
constexpr float kAmbient = 0.12f;

Vec3 sky(const Vec3& dir) {
    const float k = 0.5f * (dir.y + 1.f);
    return Vec3{0.9f, 0.95f, 1.f} * (1.f - k) + Vec3{0.35f, 0.55f, 0.9f} * k;
}

struct TileGrid {
    int tile, cols, rows;
    std::size_t count() const { return static_cast<std::size_t>(cols) * rows; }
};

// Buffers of one worker, allocated once per render, reused for every tile.
struct TileWork {
    std::vector<Ray> rays, shadow_rays;
    std::vector<Hit> hits;
    std::vector<std::uint8_t> occluded;
    std::vector<Vec3> normals, points;
    std::vector<std::uint32_t> shadow_pixel;
    TraversalCounters primary, shadow;
    std::uint64_t shadow_ray_count = 0;
};

void render_tile(const Scene& scene, const Accelerator& accel, const PinholeCamera& camera, const TileGrid& grid,
                 std::size_t tile_index, bool count, TileWork& w, Image& image) {
    const int x0 = static_cast<int>(tile_index % grid.cols) * grid.tile;
    const int y0 = static_cast<int>(tile_index / grid.cols) * grid.tile;
    const int x1 = std::min(x0 + grid.tile, image.width), y1 = std::min(y0 + grid.tile, image.height);
    w.rays.clear();
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) w.rays.push_back(camera.primary(x, y));
    w.hits.resize(w.rays.size());
    accel.intersect(w.rays, w.hits, count ? &w.primary : nullptr);

    w.shadow_rays.clear();
    w.shadow_pixel.clear();
    w.normals.resize(w.rays.size());
    for (std::size_t i = 0; i < w.rays.size(); ++i) {
        const Hit& h = w.hits[i];
        if (!h.is_hit()) continue;
        const Triangle& tri = scene.triangles[h.prim];
        Vec3 n = normalize(tri.geometric_normal());
        if (dot(n, w.rays[i].dir) > 0.f) n = -n;  // face the viewer
        w.normals[i] = n;
        const Vec3 p = tri.v0 * (1.f - h.u - h.v) + tri.v1 * h.u + tri.v2 * h.v;
        Ray s;
        s.org = offset_ray_origin(p, n);
        const Vec3 to_light = scene.light.position - s.org;
        const float dist = length(to_light);
        s.dir = to_light * (1.f / dist);
        s.tnear = 0.f;
        s.tfar = dist * 0.9999f;  // stop just short of the light itself
        w.shadow_rays.push_back(s);
        w.shadow_pixel.push_back(static_cast<std::uint32_t>(i));
    }
    w.shadow_ray_count += w.shadow_rays.size();
    w.occluded.resize(w.shadow_rays.size());
    accel.occluded(w.shadow_rays, w.occluded, count ? &w.shadow : nullptr);

    const int tw = x1 - x0;
    for (std::size_t i = 0; i < w.rays.size(); ++i)
        if (!w.hits[i].is_hit()) image.at(x0 + static_cast<int>(i) % tw, y0 + static_cast<int>(i) / tw) = sky(w.rays[i].dir);
    for (std::size_t k = 0; k < w.shadow_rays.size(); ++k) {
        const std::uint32_t i = w.shadow_pixel[k];
        const float lambert = w.occluded[k] ? 0.f : std::max(0.f, dot(w.normals[i], w.shadow_rays[k].dir));
        image.at(x0 + static_cast<int>(i) % tw, y0 + static_cast<int>(i) / tw) =
            kAlbedo * (kAmbient + lambert) * scene.light.color;
    }
}

}  // namespace

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

Image render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, RenderStats* stats) {
    const PinholeCamera camera(scene.camera, options.width, options.height);
    if (options.tile < 1) throw Error("tile size must be positive");
    Image image(options.width, options.height);
    const TileGrid grid{options.tile, (options.width + options.tile - 1) / options.tile,
                        (options.height + options.tile - 1) / options.tile};
    const unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());

    Timer timer;
    std::atomic<std::size_t> next{0}, done{0};
    std::mutex merge;
    RenderStats total;
    auto worker = [&] {
        TileWork work;
        for (std::size_t t = next++; t < grid.count(); t = next++) {
            if (options.cancel && options.cancel->load(std::memory_order_relaxed)) break;
            render_tile(scene, accel, camera, grid, t, options.count, work, image);
            const std::size_t finished = ++done;
            if (options.progress) options.progress(finished, grid.count());
        }
        std::lock_guard lock(merge);
        total.primary += work.primary;
        total.shadow += work.shadow;
        total.shadow_rays += work.shadow_ray_count;
    };
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < threads; ++i) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
    if (options.cancel && options.cancel->load()) throw Error("render cancelled");

    if (stats) {
        *stats = total;
        stats->seconds = timer.seconds();
        stats->primary_rays = static_cast<std::uint64_t>(options.width) * options.height;
    }
    return image;
}

}  // namespace cellrt
