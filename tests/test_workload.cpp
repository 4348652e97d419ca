// The frame workload (workload.hpp): a packet's primary rays are the camera's rays of its pixels in
// packet order, each hit casts one shadow ray and a miss none; the renderer traces exactly the rays
// frame_rays() collects for the benchmark and the cache study.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <vector>

#include "cellrt/builtin.hpp"
#include "cellrt/render.hpp"
#include "cellrt/workload.hpp"

namespace cellrt {
namespace {

bool same_rays(std::span<const Ray> a, std::span<const Ray> b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

// A size whose edge packets are cut on both sides, so partial packets are covered.
constexpr int kWidth = 37, kHeight = 29, kPacket = 8;

TEST(Workload, PrimaryRaysAreTheCamerasInPacketOrderAndEveryHitCastsOneShadowRay) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"brute"});
    const PinholeCamera camera(scene.camera, kWidth, kHeight);
    const PacketGrid grid(kWidth, kHeight, kPacket);
    PacketWorkload work(scene, camera, kPacket * kPacket);
    std::size_t hits = 0, misses = 0;
    for (std::size_t p = 0; p < grid.count(); ++p) {
        const PixelRect rect = grid.rect(p);
        TraversalCounters primary, shadow;
        work.trace(rect, *accel, &primary, &shadow);

        std::vector<std::uint32_t> order(static_cast<std::size_t>(rect.pixels()));
        packet_order(rect, order);
        ASSERT_TRUE(std::equal(order.begin(), order.end(), work.order().begin(), work.order().end())) << p;
        std::vector<Ray> expected;
        for (const std::uint32_t o : order)
            expected.push_back(camera.primary(rect.x0 + static_cast<int>(o) % rect.width(),
                                              rect.y0 + static_cast<int>(o) / rect.width()));
        ASSERT_TRUE(same_rays(work.primary(), expected)) << "packet " << p;
        std::vector<Hit> expected_hits(expected.size());
        accel->intersect(expected, expected_hits);
        ASSERT_TRUE(std::equal(expected_hits.begin(), expected_hits.end(), work.hits().begin(), work.hits().end()));
        EXPECT_EQ(primary.rays, expected.size());

        // One shadow ray per hit, in the primary rays' order, none for a miss.
        std::vector<Ray> expected_shadow;
        std::vector<std::uint32_t> expected_primary;
        for (std::size_t i = 0; i < expected.size(); ++i) {
            if (!expected_hits[i].is_hit()) {
                ++misses;
                continue;
            }
            ++hits;
            const SurfacePoint sp = surface_point(scene.triangles[expected_hits[i].prim], expected[i], expected_hits[i]);
            expected_shadow.push_back(shadow_ray(sp.position, sp.normal, scene.light.position));
            expected_primary.push_back(static_cast<std::uint32_t>(i));
            EXPECT_EQ(work.normals()[expected_shadow.size() - 1], sp.normal);
        }
        ASSERT_TRUE(same_rays(work.shadow(), expected_shadow)) << "packet " << p;
        EXPECT_TRUE(std::equal(expected_primary.begin(), expected_primary.end(), work.shadow_primary().begin(),
                               work.shadow_primary().end()));
        EXPECT_EQ(shadow.rays, expected_shadow.size());
        std::vector<std::uint8_t> occluded(expected_shadow.size());
        accel->occluded(expected_shadow, occluded);
        EXPECT_TRUE(std::equal(occluded.begin(), occluded.end(), work.occluded().begin(), work.occluded().end()));
    }
    EXPECT_GT(hits, 0u);
    EXPECT_GT(misses, 0u) << "the scene must show some sky";
}

// Records every batch it is given, in order, and answers through another accelerator.
class RecordingAccelerator : public Accelerator {
public:
    explicit RecordingAccelerator(const Accelerator& inner) : inner_(inner) {}
    void intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        record(intersected, rays);
        inner_.intersect(rays, hits, counters);
    }
    void occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded, TraversalCounters* counters) const override {
        record(occlusion_tested, rays);
        inner_.occluded(rays, occluded, counters);
    }
    AccelStats stats() const override { return inner_.stats(); }

    mutable std::vector<std::vector<Ray>> intersected, occlusion_tested;

private:
    void record(std::vector<std::vector<Ray>>& to, std::span<const Ray> rays) const {
        const std::lock_guard lock(mutex_);
        to.emplace_back(rays.begin(), rays.end());
    }
    const Accelerator& inner_;
    mutable std::mutex mutex_;
};

// One worker traces the packets in the grid's order, so its batches are the frame's packets one by one.
TEST(Workload, TheRendererTracesTheRaysThatFrameRaysCollects) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto brute = make_accelerator(scene.triangles, AccelConfig{"brute"});
    const RecordingAccelerator recording(*brute);
    RenderOptions o;
    o.width = kWidth;
    o.height = kHeight;
    o.packet = kPacket;
    o.threads = 1;
    RenderStats stats;
    render(scene, recording, o, &stats);

    const FrameRays f = frame_rays(scene, kWidth, kHeight, kPacket, *make_accelerator(scene.triangles, AccelConfig{"kd"}));
    const PacketGrid grid(kWidth, kHeight, kPacket);
    ASSERT_EQ(f.packets.size(), grid.count());
    ASSERT_EQ(recording.intersected.size(), grid.count());
    ASSERT_EQ(recording.occlusion_tested.size(), grid.count());
    for (std::size_t p = 0; p < grid.count(); ++p) {
        const FrameRays::Packet& packet = f.packets[p];
        EXPECT_EQ(packet.index, p);
        EXPECT_TRUE(same_rays(recording.intersected[p], std::span(f.primary).subspan(packet.primary, packet.primary_count)))
            << "primary rays of packet " << p;
        EXPECT_TRUE(same_rays(recording.occlusion_tested[p], std::span(f.shadow).subspan(packet.shadow, packet.shadow_count)))
            << "shadow rays of packet " << p;
    }
    EXPECT_EQ(f.primary.size(), stats.primary_rays);
    EXPECT_EQ(f.shadow.size(), stats.shadow_rays);
    EXPECT_EQ(f.frame_ray_count, stats.primary_rays + stats.shadow_rays);
}

// The cache study keeps a sample of the packets: each kept packet has the very rays it has in the
// whole frame (the benchmark's), and the frame's ray count is still the whole frame's.
TEST(Workload, KeptPacketsHaveTheirRaysInTheWholeFrame) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto kd = make_accelerator(scene.triangles, AccelConfig{"kd"});
    const FrameRays all = frame_rays(scene, kWidth, kHeight, kPacket, *kd);
    const FrameRays some = frame_rays(scene, kWidth, kHeight, kPacket, *kd, [](std::size_t p) { return p % 3 == 1; });
    EXPECT_EQ(some.frame_ray_count, all.frame_ray_count);
    EXPECT_EQ(all.frame_ray_count, all.primary.size() + all.shadow.size());
    std::vector<std::size_t> kept;
    for (const FrameRays::Packet& k : some.packets) kept.push_back(k.index);
    EXPECT_EQ(kept, (std::vector<std::size_t>{1, 4, 7, 10, 13, 16, 19}));  // of the 5 x 4 packets
    for (const FrameRays::Packet& k : some.packets) {
        const FrameRays::Packet& a = all.packets[k.index];
        EXPECT_TRUE(same_rays(std::span(some.primary).subspan(k.primary, k.primary_count),
                              std::span(all.primary).subspan(a.primary, a.primary_count)));
        EXPECT_TRUE(same_rays(std::span(some.shadow).subspan(k.shadow, k.shadow_count),
                              std::span(all.shadow).subspan(a.shadow, a.shadow_count)));
    }
}

}  // namespace
}  // namespace cellrt
