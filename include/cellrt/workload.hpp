// The frame workload: the rays of a frame as the renderer traces them, packet by packet. A P x P
// packet (schedule.hpp) is its primary rays in packet order (Morton order), one batch, and then one
// shadow ray toward the point light per primary hit, one batch. The renderer shades these rays; the
// accelerator benchmark and the cache study trace the very same ones.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/schedule.hpp"

namespace cellrt {

// One packet's rays and what the accelerator answered, in buffers kept from packet to packet: a worker
// holds one and traces packet after packet without allocating, for packets of up to `max_pixels`.
// `scene` and `camera` must outlive it.
class PacketWorkload {
public:
    PacketWorkload(const Scene& scene, const PinholeCamera& camera, std::size_t max_pixels);
    PacketWorkload(PacketWorkload&&) noexcept;
    PacketWorkload& operator=(PacketWorkload&&) noexcept;
    ~PacketWorkload();

    // Traces the packet `rect` through `accel`: its primary rays, then the shadow rays of their hits.
    // Each batch's counters are added to `primary` and `shadow` where given.
    void trace(const PixelRect& rect, const Accelerator& accel, TraversalCounters* primary = nullptr,
               TraversalCounters* shadow = nullptr);

    // Primary ray i is the camera's ray through pixel order()[i] of the rect (offset y * width + x
    // within it); hits()[i] is its closest hit.
    std::span<const std::uint32_t> order() const;
    std::span<const Ray> primary() const;
    std::span<const Hit> hits() const;

    // One shadow ray per primary hit, in the order of the primary rays: shadow ray k starts at the hit
    // of primary ray shadow_primary()[k], where the surface normal facing the camera is normals()[k];
    // occluded()[k] is 1 when something lies between that point and the light.
    std::span<const Ray> shadow() const;
    std::span<const std::uint32_t> shadow_primary() const;
    std::span<const Vec3> normals() const;
    std::span<const std::uint8_t> occluded() const;

private:
    struct Buffers;
    const Scene* scene_;
    const PinholeCamera* camera_;
    std::unique_ptr<Buffers> buffers_;  // on cache lines of their own (workers write them on every packet)
};

// The rays of some of a frame's packets, packet after packet in the grid's (row-major) order: each
// packet's primary rays in packet order, and apart from them its shadow rays.
struct FrameRays {
    struct Packet {
        std::size_t index;                   // in the PacketGrid
        std::size_t primary, primary_count;  // its rays in `primary`
        std::size_t shadow, shadow_count;    // its rays in `shadow`
    };
    std::vector<Packet> packets;
    std::vector<Ray> primary, shadow;
    std::uint64_t frame_ray_count = 0;  // primary and shadow rays of every packet of the frame, kept or not
};

// The frame workload of a width x height frame in packets of `packet` x `packet` pixels, with the hits
// `accel` finds (each of cellrt's structures finds the same under the hit rule, so its shadow rays are
// every structure's), keeping the packets whose index `keep` accepts (all without it). Throws
// cellrt::Error for a bad size or packet edge.
FrameRays frame_rays(const Scene& scene, int width, int height, int packet, const Accelerator& accel,
                     const std::function<bool(std::size_t)>& keep = {});

}  // namespace cellrt
