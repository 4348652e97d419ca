#include "cellrt/workload.hpp"

#include <array>

#include "cellrt/render.hpp"
#include "cellrt/sampling.hpp"
#include "kernel/named.hpp"
#include "schedule/cache_line.hpp"

namespace cellrt {
namespace {

constexpr detail::Named<Shading> kShadings[] = {
    {"direct", Shading::direct}, {"ao", Shading::ao}, {"diffuse", Shading::diffuse}};
constexpr detail::Named<RayKind> kRayKindNames[] = {{"primary", RayKind::primary},
                                                    {"shadow", RayKind::shadow},
                                                    {"ao", RayKind::ao},
                                                    {"bounce", RayKind::bounce},
                                                    {"bounce shadow", RayKind::bounce_shadow}};

}  // namespace

Shading parse_shading(const std::string& name) { return detail::value_named(kShadings, name, "shading"); }
const char* to_string(Shading s) { return detail::name_of(kShadings, s); }
std::vector<std::string> shading_names() { return detail::names_of(kShadings); }
const char* to_string(RayKind k) { return detail::name_of(kRayKindNames, k); }

namespace {

void check_ao_samples(int samples) {
    if (samples < 1 || samples > kMaxAoSamples)
        throw Error("AO samples " + std::to_string(samples) + " must lie in [1, " + std::to_string(kMaxAoSamples) +
                    "]");
}

}  // namespace

FrameShading frame_shading(const Scene& scene, const PinholeCamera& camera, const ShadingOptions& shading) {
    check_ao_samples(shading.ao_samples);
    FrameShading f;
    f.camera = camera.projection();
    f.light_position = scene.light.position;
    f.light_color = scene.light.color;
    f.shading = shading;
    // Only AO rays reach that far: the scene's box reads every triangle (0.27 ms on Sponza, 1.5 % of a
    // 384 x 384 direct frame of the bunny), so other shadings leave it at 0.
    if (shading.shading == Shading::ao) f.ao_reach = kAoReachFraction * length(scene.bounds().extent());
    f.frame_width = camera.width();
    return f;
}

RayKind secondary_kind(Shading s) {
    switch (s) {
        case Shading::ao: return RayKind::ao;
        case Shading::diffuse: return RayKind::bounce;
        case Shading::direct: break;
    }
    return RayKind::shadow;
}

// One kind's rays of a packet, what they were cast from and the accelerator's answers.
struct RayBuffers {
    CacheLineVector<Ray> rays;
    CacheLineVector<std::uint32_t> parent;
    CacheLineVector<Vec3> normals;
    CacheLineVector<Hit> hits;
    CacheLineVector<std::uint8_t> occluded;

    void reserve(std::size_t n) {
        rays.reserve(n);
        parent.reserve(n);
        normals.reserve(n);
        hits.reserve(n);
        occluded.reserve(n);
    }
    void clear() {
        rays.clear();
        parent.clear();
        normals.clear();
        hits.clear();
        occluded.clear();
    }
    void add(const Ray& r, std::size_t from, const Vec3& normal) {
        rays.push_back(r);
        parent.push_back(static_cast<std::uint32_t>(from));
        normals.push_back(normal);
    }
    void trace(const Accelerator& accel, RayKind kind, TraversalCounters* counters) {
        if (closest_hit(kind)) {
            hits.resize(rays.size());
            accel.intersect(rays, hits, counters);
        } else {
            occluded.resize(rays.size());
            accel.occluded(rays, occluded, counters);
        }
    }
    RayBatch view() const { return {rays, parent, normals, hits, occluded}; }
};

// Kept on lines of their own: per-worker buffers are allocated one after another on one thread, and
// a line shared by two workers' buffers would pass between their cores on every packet
// (schedule/cache_line.hpp).
struct alignas(kCacheLine) PacketWorkload::Buffers {
    CacheLineVector<std::uint32_t> order;
    int order_width = 0, order_height = 0;  // the packet shape `order` was made for
    std::size_t max_pixels = 0;             // the largest packet the buffers were reserved for
    CacheLineVector<std::uint64_t> pixel;   // primary ray i's pixel index in the frame
    std::array<RayBuffers, kRayKinds> kinds;

    RayBuffers& operator[](RayKind k) { return kinds[static_cast<std::size_t>(k)]; }
    const RayBuffers& operator[](RayKind k) const { return kinds[static_cast<std::size_t>(k)]; }
};

PacketWorkload::PacketWorkload(const Scene& scene, const PinholeCamera& camera, std::size_t max_pixels,
                               const ShadingOptions& shading)
    : PacketWorkload(scene, frame_shading(scene, camera, shading), max_pixels) {}

PacketWorkload::PacketWorkload(const Scene& scene, const FrameShading& frame, std::size_t max_pixels)
    : scene_(&scene), frame_(frame), buffers_(std::make_unique<Buffers>()) {
    check_ao_samples(frame.shading.ao_samples);  // a FrameShading made by hand
    Buffers& b = *buffers_;
    b.max_pixels = max_pixels;
    b.order.reserve(max_pixels);
    b.pixel.reserve(max_pixels);
    b[RayKind::primary].reserve(max_pixels);
    switch (frame.shading.shading) {
        case Shading::direct: b[RayKind::shadow].reserve(max_pixels); break;
        case Shading::ao:
            b[RayKind::ao].reserve(max_pixels * static_cast<std::size_t>(frame.shading.ao_samples));
            break;
        case Shading::diffuse:
            for (RayKind k : {RayKind::shadow, RayKind::bounce, RayKind::bounce_shadow}) b[k].reserve(max_pixels);
            break;
    }
}

PacketWorkload::PacketWorkload(PacketWorkload&&) noexcept = default;
PacketWorkload& PacketWorkload::operator=(PacketWorkload&&) noexcept = default;
PacketWorkload::~PacketWorkload() = default;

void PacketWorkload::trace(const PixelRect& rect, const Accelerator& accel, TraversalCounters* primary,
                           TraversalCounters* secondary) {
    Buffers& b = *buffers_;
    // A rect outside the frame would trace rays of pixels that do not exist (and seed them as pixels
    // of the next row); one larger than the buffers would allocate in the middle of a frame.
    const int width = static_cast<int>(frame_.camera.width), height = static_cast<int>(frame_.camera.height);
    if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > width || rect.y1 > height || rect.x0 >= rect.x1 ||
        rect.y0 >= rect.y1 || static_cast<std::size_t>(rect.pixels()) > b.max_pixels)
        throw Error("PacketWorkload::trace: packet [" + std::to_string(rect.x0) + ", " + std::to_string(rect.x1) + ") x [" +
                    std::to_string(rect.y0) + ", " + std::to_string(rect.y1) + ") is empty, outside the " +
                    std::to_string(width) + "x" + std::to_string(height) +
                    " frame or larger than the workload's " + std::to_string(b.max_pixels) + " pixels");
    if (rect.width() != b.order_width || rect.height() != b.order_height) {  // only edge packets differ
        b.order.resize(static_cast<std::size_t>(rect.pixels()));
        packet_order(rect, b.order);
        b.order_width = rect.width();
        b.order_height = rect.height();
    }
    for (RayBuffers& k : b.kinds) k.clear();
    b.pixel.clear();
    RayBuffers& prim = b[RayKind::primary];
    for (const std::uint32_t p : b.order) {
        const int x = rect.x0 + static_cast<int>(p) % rect.width(), y = rect.y0 + static_cast<int>(p) / rect.width();
        prim.rays.push_back(frame_.camera.primary(x, y));
        b.pixel.push_back(static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(frame_.frame_width) +
                          static_cast<std::uint64_t>(x));
    }
    prim.trace(accel, RayKind::primary, primary);

    const Vec3 light = frame_.light_position;
    for (std::size_t i = 0; i < prim.rays.size(); ++i) {
        const Hit& h = prim.hits[i];
        if (!h.is_hit()) continue;
        const SurfacePoint sp = surface_point(scene_->triangles[h.prim], prim.rays[i], h);
        switch (frame_.shading.shading) {
            case Shading::direct: b[RayKind::shadow].add(shadow_ray(sp, light), i, sp.normal); break;
            case Shading::ao:
                for (int s = 0; s < frame_.shading.ao_samples; ++s)
                    b[RayKind::ao].add(hemisphere_ray(sp, b.pixel[i], static_cast<std::uint32_t>(s), kAoDims, frame_.ao_reach),
                                       i, sp.normal);
                break;
            case Shading::diffuse:
                b[RayKind::shadow].add(shadow_ray(sp, light), i, sp.normal);
                b[RayKind::bounce].add(hemisphere_ray(sp, b.pixel[i], 0, kBounceDims, kInfinity), i, sp.normal);
                break;
        }
    }
    // Every batch the shading casts is traced, empty or not: an accelerator sees the same calls for
    // every packet.
    if (frame_.shading.shading == Shading::ao) {
        b[RayKind::ao].trace(accel, RayKind::ao, secondary);
        return;
    }
    b[RayKind::shadow].trace(accel, RayKind::shadow, secondary);
    if (frame_.shading.shading == Shading::direct) return;

    RayBuffers& bounce = b[RayKind::bounce];
    bounce.trace(accel, RayKind::bounce, secondary);
    RayBuffers& bounce_shadow = b[RayKind::bounce_shadow];
    for (std::size_t j = 0; j < bounce.rays.size(); ++j) {
        const Hit& h = bounce.hits[j];
        if (!h.is_hit()) continue;
        const SurfacePoint sp = surface_point(scene_->triangles[h.prim], bounce.rays[j], h);
        bounce_shadow.add(shadow_ray(sp, light), j, sp.normal);
    }
    bounce_shadow.trace(accel, RayKind::bounce_shadow, secondary);
}

std::span<const std::uint32_t> PacketWorkload::order() const { return buffers_->order; }
RayBatch PacketWorkload::batch(RayKind k) const { return (*buffers_)[k].view(); }

std::size_t PacketWorkload::ray_count() const {
    std::size_t n = 0;
    for (const RayBuffers& k : buffers_->kinds) n += k.rays.size();
    return n;
}

FrameRays frame_rays(const Scene& scene, int width, int height, int packet, const Accelerator& accel,
                     const ShadingOptions& shading, const std::function<bool(std::size_t)>& keep) {
    const PacketGrid grid(width, height, packet);
    const PinholeCamera camera(scene.camera, width, height);
    PacketWorkload work(scene, camera, static_cast<std::size_t>(packet) * static_cast<std::size_t>(packet), shading);
    FrameRays f;
    f.secondary_kind = secondary_kind(shading.shading);
    for (std::size_t p = 0; p < grid.count(); ++p) {
        work.trace(grid.rect(p), accel);
        f.frame_ray_count += work.ray_count();
        if (keep && !keep(p)) continue;
        const std::span<const Ray> primary = work.batch(RayKind::primary).rays;
        const std::span<const Ray> secondary = work.batch(f.secondary_kind).rays;
        f.packets.push_back({p, f.primary.size(), primary.size(), f.secondary.size(), secondary.size()});
        f.primary.insert(f.primary.end(), primary.begin(), primary.end());
        f.secondary.insert(f.secondary.end(), secondary.begin(), secondary.end());
    }
    return f;
}

}  // namespace cellrt
