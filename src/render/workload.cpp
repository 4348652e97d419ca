#include "cellrt/workload.hpp"

#include "cellrt/render.hpp"
#include "schedule/cache_line.hpp"

namespace cellrt {

// Kept on lines of their own: per-worker buffers are allocated one after another on one thread, and
// a line shared by two workers' buffers would pass between their cores on every packet
// (schedule/cache_line.hpp).
struct alignas(kCacheLine) PacketWorkload::Buffers {
    CacheLineVector<std::uint32_t> order;
    int order_width = 0, order_height = 0;  // the packet shape `order` was made for
    CacheLineVector<Ray> primary, shadow;
    CacheLineVector<Hit> hits;
    CacheLineVector<std::uint32_t> shadow_primary;
    CacheLineVector<Vec3> normals;
    CacheLineVector<std::uint8_t> occluded;
};

PacketWorkload::PacketWorkload(const Scene& scene, const PinholeCamera& camera, std::size_t max_pixels)
    : scene_(&scene), camera_(&camera), buffers_(std::make_unique<Buffers>()) {
    Buffers& b = *buffers_;
    b.order.reserve(max_pixels);
    b.primary.reserve(max_pixels);
    b.shadow.reserve(max_pixels);
    b.hits.reserve(max_pixels);
    b.shadow_primary.reserve(max_pixels);
    b.normals.reserve(max_pixels);
    b.occluded.reserve(max_pixels);
}

PacketWorkload::PacketWorkload(PacketWorkload&&) noexcept = default;
PacketWorkload& PacketWorkload::operator=(PacketWorkload&&) noexcept = default;
PacketWorkload::~PacketWorkload() = default;

void PacketWorkload::trace(const PixelRect& rect, const Accelerator& accel, TraversalCounters* primary,
                           TraversalCounters* shadow) {
    Buffers& b = *buffers_;
    if (rect.width() != b.order_width || rect.height() != b.order_height) {  // only edge packets differ
        b.order.resize(static_cast<std::size_t>(rect.pixels()));
        packet_order(rect, b.order);
        b.order_width = rect.width();
        b.order_height = rect.height();
    }
    b.primary.clear();
    for (const std::uint32_t p : b.order)
        b.primary.push_back(camera_->primary(rect.x0 + static_cast<int>(p) % rect.width(),
                                             rect.y0 + static_cast<int>(p) / rect.width()));
    b.hits.resize(b.primary.size());
    accel.intersect(b.primary, b.hits, primary);

    b.shadow.clear();
    b.shadow_primary.clear();
    b.normals.clear();
    for (std::size_t i = 0; i < b.primary.size(); ++i) {
        const Hit& h = b.hits[i];
        if (!h.is_hit()) continue;
        const SurfacePoint sp = surface_point(scene_->triangles[h.prim], b.primary[i], h);
        b.shadow.push_back(shadow_ray(sp.position, sp.normal, scene_->light.position));
        b.shadow_primary.push_back(static_cast<std::uint32_t>(i));
        b.normals.push_back(sp.normal);
    }
    b.occluded.resize(b.shadow.size());
    accel.occluded(b.shadow, b.occluded, shadow);
}

std::span<const std::uint32_t> PacketWorkload::order() const { return buffers_->order; }
std::span<const Ray> PacketWorkload::primary() const { return buffers_->primary; }
std::span<const Hit> PacketWorkload::hits() const { return buffers_->hits; }
std::span<const Ray> PacketWorkload::shadow() const { return buffers_->shadow; }
std::span<const std::uint32_t> PacketWorkload::shadow_primary() const { return buffers_->shadow_primary; }
std::span<const Vec3> PacketWorkload::normals() const { return buffers_->normals; }
std::span<const std::uint8_t> PacketWorkload::occluded() const { return buffers_->occluded; }

FrameRays frame_rays(const Scene& scene, int width, int height, int packet, const Accelerator& accel,
                     const std::function<bool(std::size_t)>& keep) {
    const PacketGrid grid(width, height, packet);
    const PinholeCamera camera(scene.camera, width, height);
    PacketWorkload work(scene, camera, static_cast<std::size_t>(packet) * static_cast<std::size_t>(packet));
    FrameRays f;
    for (std::size_t p = 0; p < grid.count(); ++p) {
        work.trace(grid.rect(p), accel);
        f.frame_ray_count += work.primary().size() + work.shadow().size();
        if (keep && !keep(p)) continue;
        f.packets.push_back({p, f.primary.size(), work.primary().size(), f.shadow.size(), work.shadow().size()});
        f.primary.insert(f.primary.end(), work.primary().begin(), work.primary().end());
        f.shadow.insert(f.shadow.end(), work.shadow().begin(), work.shadow().end());
    }
    return f;
}

}  // namespace cellrt
