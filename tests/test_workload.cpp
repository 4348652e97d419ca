// The frame workload (workload.hpp): a packet's primary rays are the camera's rays of its pixels in
// packet order; under direct shading each hit casts one shadow ray and a miss none; under AO N
// cosine-weighted rays about the normal; under diffuse a shadow ray and a bounce, and each bounce's
// hit a shadow ray. A pixel's rays do not depend on the packet size; the renderer traces exactly the
// rays frame_rays() collects for the benchmark and the cache study.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <numbers>
#include <vector>

#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "cellrt/sampling.hpp"
#include "cellrt/workload.hpp"
#include "error_of.hpp"

namespace cellrt {
namespace {

// memcmp must not be given a null pointer even for 0 bytes, and an empty span's data() may be one.
bool same_rays(std::span<const Ray> a, std::span<const Ray> b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size_bytes()) == 0);
}

// A size whose edge packets are cut on both sides, so partial packets are covered.
constexpr int kWidth = 37, kHeight = 29, kPacket = 8;

ShadingOptions shading_of(Shading s, int ao_samples = 4) {
    ShadingOptions o;
    o.shading = s;
    o.ao_samples = ao_samples;
    return o;
}

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
        const RayBatch prim = work.batch(RayKind::primary), sh = work.batch(RayKind::shadow);

        std::vector<std::uint32_t> order(static_cast<std::size_t>(rect.pixels()));
        packet_order(rect, order);
        ASSERT_TRUE(std::equal(order.begin(), order.end(), work.order().begin(), work.order().end())) << p;
        std::vector<Ray> expected;
        for (const std::uint32_t o : order)
            expected.push_back(camera.primary(rect.x0 + static_cast<int>(o) % rect.width(),
                                              rect.y0 + static_cast<int>(o) / rect.width()));
        ASSERT_TRUE(same_rays(prim.rays, expected)) << "packet " << p;
        std::vector<Hit> expected_hits(expected.size());
        accel->intersect(expected, expected_hits);
        ASSERT_TRUE(std::equal(expected_hits.begin(), expected_hits.end(), prim.hits.begin(), prim.hits.end()));
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
            expected_shadow.push_back(shadow_ray(sp, scene.light.position));
            expected_primary.push_back(static_cast<std::uint32_t>(i));
            EXPECT_EQ(sh.normals[expected_shadow.size() - 1], sp.normal);
        }
        ASSERT_TRUE(same_rays(sh.rays, expected_shadow)) << "packet " << p;
        EXPECT_TRUE(std::equal(expected_primary.begin(), expected_primary.end(), sh.parent.begin(), sh.parent.end()));
        EXPECT_EQ(shadow.rays, expected_shadow.size());
        std::vector<std::uint8_t> occluded(expected_shadow.size());
        accel->occluded(expected_shadow, occluded);
        EXPECT_TRUE(std::equal(occluded.begin(), occluded.end(), sh.occluded.begin(), sh.occluded.end()));
    }
    EXPECT_GT(hits, 0u);
    EXPECT_GT(misses, 0u) << "the scene must show some sky";
}

// Under AO, each hit casts --ao-samples rays, consecutive, from the shadow ray's origin, about the
// normal, reaching a tenth of the scene's diagonal; their cosines to the normal average 2/3, as a
// cosine-weighted hemisphere's do (a uniform hemisphere's average 1/2).
TEST(Workload, AoRaysAreCosineWeightedAboutTheNormalWithAFixedReach) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"kd"});
    const PinholeCamera camera(scene.camera, kWidth, kHeight);
    const PacketGrid grid(kWidth, kHeight, kPacket);
    const int n = 5;
    PacketWorkload work(scene, camera, kPacket * kPacket, shading_of(Shading::ao, n));
    const float reach = kAoReachFraction * length(scene.bounds().extent());
    double cosines = 0;
    std::size_t rays = 0;
    for (std::size_t p = 0; p < grid.count(); ++p) {
        work.trace(grid.rect(p), *accel);
        const RayBatch prim = work.batch(RayKind::primary), ao = work.batch(RayKind::ao);
        EXPECT_TRUE(work.batch(RayKind::shadow).rays.empty());
        const auto hits = static_cast<std::size_t>(std::count_if(prim.hits.begin(), prim.hits.end(),
                                                                 [](const Hit& h) { return h.is_hit(); }));
        ASSERT_EQ(ao.rays.size(), hits * n) << p;
        ASSERT_EQ(ao.occluded.size(), ao.rays.size());
        for (std::size_t k = 0; k < ao.rays.size(); ++k) {
            const std::uint32_t i = ao.parent[k];
            ASSERT_EQ(i, ao.parent[k - k % n]) << "the rays of a hit are consecutive";
            const SurfacePoint sp = surface_point(scene.triangles[prim.hits[i].prim], prim.rays[i], prim.hits[i]);
            EXPECT_EQ(ao.normals[k], sp.normal);
            EXPECT_EQ(ao.rays[k].org, offset_ray_origin(sp));
            EXPECT_EQ(ao.rays[k].tnear, 0.f);
            EXPECT_EQ(ao.rays[k].tfar, reach);
            EXPECT_NEAR(length(ao.rays[k].dir), 1.f, 1e-5f);
            EXPECT_GE(dot(ao.rays[k].dir, sp.normal), -1e-6f);
            cosines += dot(ao.rays[k].dir, sp.normal);
            ++rays;
        }
    }
    ASSERT_GT(rays, 1000u);
    EXPECT_NEAR(cosines / static_cast<double>(rays), 2.0 / 3.0, 0.02);
}

// Under diffuse shading each hit casts a shadow ray (as under direct) and one bounce, closest hit;
// each bounce that hits casts a shadow ray from its hit.
TEST(Workload, DiffuseRaysAreAShadowRayAndABounceAndTheBouncesShadowRays) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"kd"});
    const PinholeCamera camera(scene.camera, kWidth, kHeight);
    const PacketGrid grid(kWidth, kHeight, kPacket);
    PacketWorkload work(scene, camera, kPacket * kPacket, shading_of(Shading::diffuse));
    std::size_t bounce_hits = 0;
    for (std::size_t p = 0; p < grid.count(); ++p) {
        work.trace(grid.rect(p), *accel);
        const RayBatch prim = work.batch(RayKind::primary), sh = work.batch(RayKind::shadow),
                       bounce = work.batch(RayKind::bounce), bs = work.batch(RayKind::bounce_shadow);
        ASSERT_EQ(bounce.rays.size(), sh.rays.size());
        ASSERT_EQ(bounce.hits.size(), bounce.rays.size());
        std::vector<Ray> expected_bs;
        for (std::size_t k = 0; k < bounce.rays.size(); ++k) {
            const std::uint32_t i = bounce.parent[k];
            EXPECT_EQ(sh.parent[k], i);
            const SurfacePoint sp = surface_point(scene.triangles[prim.hits[i].prim], prim.rays[i], prim.hits[i]);
            EXPECT_EQ(sh.rays[k].org, shadow_ray(sp, scene.light.position).org);
            EXPECT_EQ(bounce.rays[k].org, sh.rays[k].org);
            EXPECT_EQ(bounce.rays[k].tfar, kInfinity);
            EXPECT_GE(dot(bounce.rays[k].dir, sp.normal), -1e-6f);
            Hit expected;
            accel->intersect(std::span(&bounce.rays[k], 1), std::span(&expected, 1));
            EXPECT_EQ(bounce.hits[k], expected);
            if (!expected.is_hit()) continue;
            const SurfacePoint bp = surface_point(scene.triangles[expected.prim], bounce.rays[k], expected);
            expected_bs.push_back(shadow_ray(bp, scene.light.position));
            EXPECT_EQ(bs.parent[expected_bs.size() - 1], k);
        }
        EXPECT_TRUE(same_rays(bs.rays, expected_bs)) << p;
        bounce_hits += expected_bs.size();
    }
    EXPECT_GT(bounce_hits, 0u);
}

// A pixel's AO and bounce rays are hashes of the pixel: the same in packets of any size.
TEST(Workload, APixelsRaysDoNotDependOnThePacketSize) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"kd"});
    const PinholeCamera camera(scene.camera, kWidth, kHeight);
    for (const Shading shading : {Shading::ao, Shading::diffuse}) {
        const RayKind kind = secondary_kind(shading);
        auto by_pixel = [&](int packet) {
            std::map<int, std::vector<Ray>> out;
            const PacketGrid grid(kWidth, kHeight, packet);
            PacketWorkload work(scene, camera, static_cast<std::size_t>(packet * packet), shading_of(shading, 3));
            for (std::size_t p = 0; p < grid.count(); ++p) {
                const PixelRect rect = grid.rect(p);
                work.trace(rect, *accel);
                const RayBatch b = work.batch(kind);
                for (std::size_t k = 0; k < b.rays.size(); ++k) {
                    const int o = static_cast<int>(work.order()[b.parent[k]]);
                    out[(rect.y0 + o / rect.width()) * kWidth + rect.x0 + o % rect.width()].push_back(b.rays[k]);
                }
            }
            return out;
        };
        const auto reference = by_pixel(kPacket);
        ASSERT_GT(reference.size(), 100u);
        for (int packet : {1, 5, 16}) {
            const auto other = by_pixel(packet);
            ASSERT_EQ(other.size(), reference.size()) << to_string(shading) << " packet " << packet;
            for (const auto& [pixel, rays] : reference)
                EXPECT_TRUE(same_rays(other.at(pixel), rays)) << to_string(shading) << " pixel " << pixel;
        }
    }
}

// A zero-area triangle the test hits (rounding gave it an area) has no normal: the surface faces
// the ray, and the shadow and bounce rays' origins are finite (the normal was NaN, and the origin's
// offset converted NaN to an integer). Normals whose length leaves float's range keep their direction.
TEST(Workload, AHitOnATriangleWithoutANormalFacesTheRay) {
    const Triangle line{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {2.f, 0.f, 0.f}};
    const Ray ray{{6.f, 1.5f, 0.0005f}, 0.f, {-4.5f, -1.5f, -0.0005f}, kInfinity};
    Hit hit;
    ASSERT_TRUE(intersect_closest(WatertightRay(ray), 0.f, line, 0u, hit));
    const SurfacePoint sp = surface_point(line, ray, hit);
    EXPECT_NEAR(length(sp.normal), 1.f, 1e-6f);
    EXPECT_LT(dot(sp.normal, ray.dir), 0.f);
    const Ray shadow = shadow_ray(sp, Vec3{0.f, 5.f, 5.f});
    for (int a = 0; a < 3; ++a) EXPECT_TRUE(std::isfinite(shadow.org[a]) && std::isfinite(shadow.dir[a]));
    // A direction too short to square (a valid ray: one component of at least 2^-126) and normals
    // whose length under- or overflows: still unit vectors, the latter the plane's own.
    const Ray tiny{{6.f, 1.5f, 0.0005f}, 0.f, Vec3{-4.5f, -1.5f, -0.0005f} * 1e-30f, kInfinity};
    EXPECT_NEAR(length(surface_point(line, tiny, hit).normal), 1.f, 1e-6f);
    const Ray down{{0.f, 0.f, 1.f}, 0.f, {0.f, 0.f, -1.f}, kInfinity};
    for (const float size : {1e-13f, 1e10f}) {
        const Triangle flat{Vec3{0.f, 0.f, 0.f}, Vec3{1.f, 0.f, 0.f} * size, Vec3{0.f, 1.f, 0.f} * size};
        const Vec3 n = surface_point(flat, down, Hit{1.f, 0u, 0.f, 0.f}).normal;
        EXPECT_EQ(n, Vec3(0.f, 0.f, 1.f)) << size;
    }
}

TEST(Workload, RefusesAnUnknownShadingAndAoSamplesOutOfRange) {
    EXPECT_EQ(parse_shading("ao"), Shading::ao);
    EXPECT_THROW(parse_shading("phong"), Error);
    const Scene scene = make_builtin_scene("builtin:spheres?tris=200");
    const PinholeCamera camera(scene.camera, 8, 8);
    for (int n : {0, -1, kMaxAoSamples + 1})
        EXPECT_THROW(PacketWorkload(scene, camera, 64, shading_of(Shading::ao, n)), Error) << n;
}

// A packet outside the frame, empty, or larger than the buffers were made for is refused before a
// ray is made (it would trace pixels that do not exist, or allocate in the middle of a frame).
TEST(Workload, RefusesAPacketOutsideTheFrameOrLargerThanItsBuffers) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=200");
    const PinholeCamera camera(scene.camera, 8, 8);
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"bvh"});
    PacketWorkload work(scene, camera, 16);
    work.trace(PixelRect{4, 4, 8, 8}, *accel);
    EXPECT_EQ(work.batch(RayKind::primary).rays.size(), 16u);
    for (const PixelRect& bad : {PixelRect{6, 6, 10, 10}, PixelRect{-1, 0, 3, 4}, PixelRect{2, 2, 2, 6},
                                 PixelRect{0, 0, 5, 4}})
        EXPECT_THROW(work.trace(bad, *accel), Error) << bad.x0 << " " << bad.y0 << " " << bad.x1 << " " << bad.y1;
    EXPECT_EQ(test::error_of([&] { work.trace(PixelRect{0, 0, 8, 9}, *accel); }),
              "PacketWorkload::trace: packet [0, 8) x [0, 9) is empty, outside the 8x8 frame or larger than the "
              "workload's 16 pixels");
}

// The frame of the hemisphere: unit directions that never point below the surface, for normals along
// the axes (both signs, where the frame's formula changes branch) and in between.
TEST(Sampling, CosineHemisphereStaysAboveTheSurface) {
    std::vector<Vec3> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, -0.f}};
    for (int i = 0; i < 200; ++i)
        normals.push_back(normalize(Vec3{hash_uniform(i, 0, 0) - 0.5f, hash_uniform(i, 0, 1) - 0.5f,
                                         hash_uniform(i, 0, 2) - 0.5f}));
    normals[6] = normalize(Vec3{1e-7f, 0.f, -1.f});
    for (const Vec3& n : normals)
        for (std::uint32_t s = 0; s < 64; ++s) {
            const Vec3 d = cosine_hemisphere(n, hash_uniform(7, s, 0), hash_uniform(7, s, 1));
            EXPECT_NEAR(length(d), 1.f, 1e-5f);
            EXPECT_GE(dot(d, n), -1e-6f);
        }
    EXPECT_NE(hash_uniform(1, 0, 0), hash_uniform(2, 0, 0));
    EXPECT_NE(hash_uniform(1, 0, 0), hash_uniform(1, 1, 0));
    EXPECT_NE(hash_uniform(1, 0, 0), hash_uniform(1, 0, 1));
}

// The cosine and sine of a turn, made of +, - and * alone so that the GPU gives the same bits: within
// 2^-22 of the C library's everywhere, at the octants' ends as inside them, and exact where they are
// (a quarter turn's cosine is 0, its sine 1).
TEST(Sampling, CosSinTurnsFollowTheCircle) {
    double worst = 0.0;
    auto check = [&](float u) {
        float c = 2.f, s = 2.f;
        cos_sin_turns(u, c, s);
        const double phi = 2.0 * std::numbers::pi * static_cast<double>(u);
        worst = std::max({worst, std::fabs(c - std::cos(phi)), std::fabs(s - std::sin(phi))});
    };
    for (int k = 0; k < 8; ++k)
        for (const float d : {0.f, 1.f / (1 << 24), 1.f / (1 << 20), 1.f / 64.f, 0.0625f, 0.1249999f})
            check(static_cast<float>(k) / 8.f + d);
    for (std::uint32_t i = 0; i < 100000; ++i) check(hash_uniform(i, 3, 1));
    EXPECT_LT(worst, 1.0 / (1 << 22));
    float c = 0.f, s = 0.f;
    cos_sin_turns(0.f, c, s);
    EXPECT_EQ(c, 1.f);
    EXPECT_EQ(s, 0.f);
    cos_sin_turns(0.25f, c, s);
    EXPECT_EQ(std::fabs(c), 0.f);
    EXPECT_EQ(s, 1.f);
    cos_sin_turns(0.5f, c, s);
    EXPECT_EQ(c, -1.f);
}

// Records every batch it is given, in order, and answers through another accelerator.
class RecordingAccelerator : public Accelerator {
public:
    explicit RecordingAccelerator(const Accelerator& inner) : inner_(inner) {}
    AccelStats stats() const override { return inner_.stats(); }

    mutable std::vector<std::vector<Ray>> intersected, occlusion_tested;

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        record(intersected, rays);
        inner_.intersect(rays, hits, counters);
    }
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        record(occlusion_tested, rays);
        inner_.occluded(rays, occluded, counters);
    }

    void record(std::vector<std::vector<Ray>>& to, std::span<const Ray> rays) const {
        const std::lock_guard lock(mutex_);
        to.emplace_back(rays.begin(), rays.end());
    }
    const Accelerator& inner_;
    mutable std::mutex mutex_;
};

// One worker traces the packets in the grid's order, so its batches are the frame's packets one by one:
// for each shading, the recorded batch of the secondary kind is frame_rays()'s.
TEST(Workload, TheRendererTracesTheRaysThatFrameRaysCollects) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto brute = make_accelerator(scene.triangles, AccelConfig{"brute"});
    const auto kd = make_accelerator(scene.triangles, AccelConfig{"kd"});
    const PacketGrid grid(kWidth, kHeight, kPacket);
    for (const Shading shading : {Shading::direct, Shading::ao, Shading::diffuse}) {
        const RecordingAccelerator recording(*brute);
        RenderOptions o;
        o.width = kWidth;
        o.height = kHeight;
        o.packet = kPacket;
        o.threads = 1;
        o.shading = shading_of(shading, 3);
        RenderStats stats;
        render(scene, recording, o, &stats);

        const FrameRays f = frame_rays(scene, kWidth, kHeight, kPacket, *kd, o.shading);
        ASSERT_EQ(f.packets.size(), grid.count());
        // Closest-hit batches per packet: primary (and bounce); any-hit: shadow or AO (and bounce shadow).
        const bool diffuse = shading == Shading::diffuse;
        ASSERT_EQ(recording.intersected.size(), grid.count() * (diffuse ? 2 : 1)) << to_string(shading);
        std::size_t all = 0;
        for (const auto& b : recording.intersected) all += b.size();
        for (const auto& b : recording.occlusion_tested) all += b.size();
        for (std::size_t p = 0; p < grid.count(); ++p) {
            const FrameRays::Packet& packet = f.packets[p];
            EXPECT_EQ(packet.index, p);
            const std::size_t first = diffuse ? 2 * p : p;
            EXPECT_TRUE(same_rays(recording.intersected[first], std::span(f.primary).subspan(packet.primary, packet.primary_count)))
                << to_string(shading) << ": primary rays of packet " << p;
            const auto secondary = std::span(f.secondary).subspan(packet.secondary, packet.secondary_count);
            const std::vector<Ray>& traced = diffuse ? recording.intersected[first + 1] : recording.occlusion_tested[p];
            EXPECT_TRUE(same_rays(traced, secondary)) << to_string(shading) << ": secondary rays of packet " << p;
        }
        EXPECT_EQ(f.primary.size(), stats.primary_rays);
        EXPECT_EQ(f.frame_ray_count, stats.primary_rays + stats.secondary_rays) << to_string(shading);
        EXPECT_EQ(all, f.frame_ray_count) << to_string(shading);
        if (!diffuse) {
            EXPECT_EQ(f.secondary.size(), stats.secondary_rays);
        }
    }
}

// The cache study keeps a sample of the packets: each kept packet has the very rays it has in the
// whole frame (the benchmark's), and the frame's ray count is still the whole frame's.
TEST(Workload, KeptPacketsHaveTheirRaysInTheWholeFrame) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=2000");
    const auto kd = make_accelerator(scene.triangles, AccelConfig{"kd"});
    const FrameRays all = frame_rays(scene, kWidth, kHeight, kPacket, *kd);
    const FrameRays some = frame_rays(scene, kWidth, kHeight, kPacket, *kd, {}, [](std::size_t p) { return p % 3 == 1; });
    EXPECT_EQ(some.frame_ray_count, all.frame_ray_count);
    EXPECT_EQ(all.frame_ray_count, all.primary.size() + all.secondary.size());
    std::vector<std::size_t> kept;
    for (const FrameRays::Packet& k : some.packets) kept.push_back(k.index);
    EXPECT_EQ(kept, (std::vector<std::size_t>{1, 4, 7, 10, 13, 16, 19}));  // of the 5 x 4 packets
    for (const FrameRays::Packet& k : some.packets) {
        const FrameRays::Packet& a = all.packets[k.index];
        EXPECT_TRUE(same_rays(std::span(some.primary).subspan(k.primary, k.primary_count),
                              std::span(all.primary).subspan(a.primary, a.primary_count)));
        EXPECT_TRUE(same_rays(std::span(some.secondary).subspan(k.secondary, k.secondary_count),
                              std::span(all.secondary).subspan(a.secondary, a.secondary_count)));
    }
}

}  // namespace
}  // namespace cellrt
