// The frame workload: the rays of a frame as the renderer traces them, packet by packet. A P x P
// packet (schedule.hpp) is its primary rays in packet order (Morton order), one batch, and then the
// rays its shading casts from their hits, a batch per kind:
//   direct   one shadow ray toward the point light per hit (the study's workload);
//   ao       N cosine-weighted rays about the normal per hit, any hit within a fixed fraction of the
//            scene's diagonal (ambient occlusion, Aila & Laine 2009's "AO" rays);
//   diffuse  a shadow ray per hit and one cosine-weighted bounce per hit, closest hit, and a shadow
//            ray from each bounce's hit (one bounce lit by the point light; Aila & Laine's "diffuse").
// The renderer shades these rays; the accelerator benchmark and the cache study trace the very same.
// Random numbers are hashes of the pixel and the sample (sampling.hpp), so a pixel's rays do not
// depend on the packet size, the schedule or the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/schedule.hpp"
#include "cellrt/shading.hpp"

namespace cellrt {

Shading parse_shading(const std::string& name);  // "direct" | "ao" | "diffuse"; throws cellrt::Error
const char* to_string(Shading s);
std::vector<std::string> shading_names();

// What the rays of a frame of `scene` seen through `camera` are made from (shading.hpp): the packets'
// workload and the GPU's frame path (shade_pixel) alike; the AO rays reach kAoReachFraction of the
// scene box's diagonal. Throws cellrt::Error for AO samples outside [1, kMaxAoSamples].
FrameShading frame_shading(const Scene& scene, const PinholeCamera& camera, const ShadingOptions& shading);

// The kinds of rays a packet casts. Primary and bounce rays ask for the closest hit, the others for
// any hit.
enum class RayKind : std::uint8_t { primary, shadow, ao, bounce, bounce_shadow };
inline constexpr int kRayKinds = 5;
const char* to_string(RayKind k);
inline bool closest_hit(RayKind k) { return k == RayKind::primary || k == RayKind::bounce; }

// The kind that follows the primary rays in a benchmark of `s`: its shadow, AO or bounce rays.
RayKind secondary_kind(Shading s);

// One batch of a packet's rays and the accelerator's answers. Ray k starts at the hit of ray
// parent[k] of the batch it was cast from (primary rays for shadow, AO and bounce rays; bounce rays
// for bounce shadow rays), where normals[k] is that surface's normal facing the side the parent came
// from. Closest-hit kinds fill `hits`, any-hit kinds `occluded` (1: something lies in the way).
struct RayBatch {
    std::span<const Ray> rays;
    std::span<const std::uint32_t> parent;  // empty for primary rays
    std::span<const Vec3> normals;          // empty for primary rays
    std::span<const Hit> hits;
    std::span<const std::uint8_t> occluded;
};

// One packet's rays and what the accelerator answered, in buffers kept from packet to packet: a worker
// holds one and traces packet after packet without allocating, for packets of up to `max_pixels`.
// `scene` is referenced, not copied: it must outlive it (the camera is copied). trace() writes the buffers,
// so a workload is one thread's (one per worker); the accelerator it is given may be shared, and must
// have been built over scene.triangles (the rays cast from a hit read the triangle it names). Throws
// cellrt::Error for AO samples out of range.
class PacketWorkload {
public:
    PacketWorkload(const Scene& scene, const PinholeCamera& camera, std::size_t max_pixels,
                   const ShadingOptions& shading = {});
    // The same, for a frame already made by frame_shading(scene, camera, shading), which for AO reads
    // every triangle (the rays' reach): the workers of one frame share one. Throws cellrt::Error for AO
    // samples out of range, as frame_shading does.
    PacketWorkload(const Scene& scene, const FrameShading& frame, std::size_t max_pixels);
    PacketWorkload(PacketWorkload&&) noexcept;
    PacketWorkload& operator=(PacketWorkload&&) noexcept;
    ~PacketWorkload();

    // Traces the packet `rect` through `accel`: its primary rays, then the rays its shading casts
    // (their random numbers seeded by the pixel's index y * width + x in the camera's frame). The
    // counters of the primary batch are added to `primary`, those of every other to `secondary`.
    // Throws cellrt::Error for a rect that is empty, reaches outside the camera's frame or has more
    // than `max_pixels` pixels.
    void trace(const PixelRect& rect, const Accelerator& accel, TraversalCounters* primary = nullptr,
               TraversalCounters* secondary = nullptr);

    // Primary ray i is the camera's ray through pixel order()[i] of the rect (offset y * width + x
    // within it).
    std::span<const std::uint32_t> order() const;
    // The batch of kind `k` (empty where the shading casts no such rays).
    RayBatch batch(RayKind k) const;
    // Rays traced for the last packet, every kind.
    std::size_t ray_count() const;
    const ShadingOptions& shading() const { return frame_.shading; }

private:
    struct Buffers;
    const Scene* scene_;
    FrameShading frame_;  // the camera, the light and the shading, as the GPU's frame path has them
    std::unique_ptr<Buffers> buffers_;  // on cache lines of their own (workers write them on every packet)
};

// The rays of some of a frame's packets, packet after packet in the grid's (row-major) order: each
// packet's primary rays in packet order, and apart from them its rays of the secondary kind.
struct FrameRays {
    struct Packet {
        std::size_t index;                         // in the PacketGrid
        std::size_t primary, primary_count;        // its rays in `primary`
        std::size_t secondary, secondary_count;    // its rays in `secondary`
    };
    RayKind secondary_kind = RayKind::shadow;
    std::vector<Packet> packets;
    std::vector<Ray> primary, secondary;
    std::uint64_t frame_ray_count = 0;  // rays of every kind of every packet of the frame, kept or not
};

// The frame workload of a width x height frame in packets of `packet` x `packet` pixels with the given
// shading, with the hits `accel` finds (each of cellrt's structures finds the same under the hit rule,
// so the rays cast from them are every structure's), keeping the packets whose index `keep` accepts
// (all without it). Throws cellrt::Error for a bad size, packet edge or AO sample count.
FrameRays frame_rays(const Scene& scene, int width, int height, int packet, const Accelerator& accel,
                     const ShadingOptions& shading = {}, const std::function<bool(std::size_t)>& keep = {});

}  // namespace cellrt
