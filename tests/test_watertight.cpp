// The reference triangle kernel: basic hits, the hit rule, and watertightness on closed meshes.
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <random>

#include "cellrt/brute_force.hpp"
#include "cellrt/triangle.hpp"
#include "scene/mesh_builder.hpp"

namespace cellrt {
namespace {

Hit closest(std::span<const Triangle> tris, const Ray& ray) {
    const auto brute = make_brute_force(tris, AccelConfig{"brute"});
    Hit h;
    brute->intersect(std::span(&ray, 1), std::span(&h, 1));
    return h;
}

TEST(Watertight, HitsTriangleAtExpectedDistanceAndBarycentrics) {
    const Triangle tri{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}};
    Ray ray;
    ray.org = {0.25f, 0.5f, 2.f};
    ray.dir = {0.f, 0.f, -1.f};
    const Hit h = closest(std::span(&tri, 1), ray);
    ASSERT_TRUE(h.is_hit());
    EXPECT_FLOAT_EQ(h.t, 2.f);
    EXPECT_FLOAT_EQ(h.u, 0.25f);
    EXPECT_FLOAT_EQ(h.v, 0.5f);
}

TEST(Watertight, RespectsIntervalEndsInclusively) {
    const Triangle tri{{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {0.f, 1.f, 0.f}};
    Ray ray;
    ray.org = {0.f, 0.f, 1.f};
    ray.dir = {0.f, 0.f, -1.f};
    ray.tfar = 1.f;
    EXPECT_TRUE(closest(std::span(&tri, 1), ray).is_hit()) << "t == tfar is a hit";
    ray.tfar = std::nextafter(1.f, 0.f);
    EXPECT_FALSE(closest(std::span(&tri, 1), ray).is_hit());
    ray.tfar = kInfinity;
    ray.tnear = 1.f;
    EXPECT_TRUE(closest(std::span(&tri, 1), ray).is_hit()) << "t == tnear is a hit";
    ray.tnear = std::nextafter(1.f, 2.f);
    EXPECT_FALSE(closest(std::span(&tri, 1), ray).is_hit());
}

TEST(Watertight, EqualDistanceGoesToLowerIndex) {
    const Triangle tri{{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {0.f, 1.f, 0.f}};
    const std::vector<Triangle> tris{{{5.f, 5.f, 5.f}, {6.f, 5.f, 5.f}, {5.f, 6.f, 5.f}}, tri, tri, tri};
    Ray ray;
    ray.org = {0.f, 0.f, 1.f};
    ray.dir = {0.f, 0.f, -1.f};
    EXPECT_EQ(closest(tris, ray).prim, 1u);
}

TEST(Watertight, DegenerateTrianglesNeverHit) {
    const std::vector<Triangle> tris{
        {{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}},      // a point
        {{-1.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}},     // a line
        {{-1.f, -1.f, 0.f}, {1.f, 1.f, 0.f}, {-1.f, -1.f, 0.f}},  // repeated vertex
    };
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    for (int i = 0; i < 2000; ++i) {
        Ray ray;
        ray.org = {u(rng), u(rng), 2.f};
        ray.dir = Vec3{0.f, 0.f, 0.f} - ray.org + Vec3{u(rng), 0.f, 0.f} * 0.1f;
        EXPECT_FALSE(closest(tris, ray).is_hit());
    }
}

TEST(Watertight, EdgeOnTriangleIsMissed) {
    const Triangle tri{{-1.f, 0.f, -1.f}, {1.f, 0.f, -1.f}, {0.f, 0.f, 1.f}};
    Ray ray;
    ray.org = {-5.f, 0.f, 0.f};
    ray.dir = {1.f, 0.f, 0.f};
    EXPECT_FALSE(closest(std::span(&tri, 1), ray).is_hit());
}

// Rays from outside aimed exactly at vertices and at points of edges of a closed convex mesh must
// hit it: a leak between triangles would let them through. Each ray comes from a direction that
// faces every triangle around its target (the summed normals at the edge's vertices, jittered), so
// no ray merely grazes a silhouette, where a miss would be legitimate.
void expect_closed_mesh_is_watertight(const std::vector<Triangle>& mesh, std::uint32_t seed) {
    const auto brute = make_brute_force(mesh, AccelConfig{"brute"});
    auto key = [](const Vec3& v) { return std::array<float, 3>{v.x, v.y, v.z}; };
    std::map<std::array<float, 3>, Vec3> vertex_normal;
    for (const Triangle& t : mesh)
        for (const Vec3& v : {t.v0, t.v1, t.v2}) vertex_normal[key(v)] += normalize(t.geometric_normal());
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.f, 1.f), unit(0.f, 1.f);
    std::uniform_int_distribution<std::size_t> pick(0, mesh.size() - 1);
    std::vector<Ray> rays;
    for (int i = 0; i < 40000; ++i) {
        const Triangle& t = mesh[pick(rng)];
        const Vec3 corners[3] = {t.v0, t.v1, t.v2};
        const Vec3& a = corners[i % 3];
        const Vec3& b = corners[(i + 1) % 3];
        const float s = i % 4 == 0 ? 0.f : (i % 4 == 1 ? 0.5f : unit(rng));
        const Vec3 target = a + (b - a) * s;
        const Vec3 outward = s == 0.f ? normalize(vertex_normal[key(a)])
                                      : normalize(normalize(vertex_normal[key(a)]) + normalize(vertex_normal[key(b)]));
        Ray r;
        r.org = target + normalize(outward + Vec3{u(rng), u(rng), u(rng)} * 0.15f) * 5.f;
        r.dir = target - r.org;
        rays.push_back(r);
    }
    std::vector<Hit> hits(rays.size());
    std::vector<std::uint8_t> occ(rays.size());
    brute->intersect(rays, hits);
    brute->occluded(rays, occ);
    std::size_t leaks = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) leaks += !hits[i].is_hit() || !occ[i];
    EXPECT_EQ(leaks, 0u) << "rays through shared edges and vertices passed between triangles";
}

TEST(Watertight, TessellatedSphereHasNoLeaks) {
    std::vector<Triangle> mesh;
    detail::MeshBuilder(mesh).sphere({0.1f, -0.2f, 0.3f}, 1.3f, 48, 24);
    expect_closed_mesh_is_watertight(mesh, 1);
}

TEST(Watertight, CubeHasNoLeaks) {
    std::vector<Triangle> mesh;
    detail::MeshBuilder(mesh).box({-1.f, -0.7f, -1.2f}, {0.9f, 1.1f, 1.3f});
    expect_closed_mesh_is_watertight(mesh, 2);
}

TEST(Watertight, InvalidRaysHitNothing) {
    const Triangle tri{{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {0.f, 1.f, 0.f}};
    const float nan = std::nanf("");
    for (const Ray& r : {Ray{{0.f, 0.f, 1.f}, 0.f, {0.f, 0.f, 0.f}, kInfinity},
                         Ray{{0.f, 0.f, 1.f}, 0.f, {nan, 0.f, -1.f}, kInfinity},
                         Ray{{nan, 0.f, 1.f}, 0.f, {0.f, 0.f, -1.f}, kInfinity},
                         Ray{{0.f, 0.f, 1.f}, 2.f, {0.f, 0.f, -1.f}, 1.f},
                         Ray{{0.f, 0.f, 1.f}, nan, {0.f, 0.f, -1.f}, kInfinity}})
        EXPECT_FALSE(closest(std::span(&tri, 1), r).is_hit());
}

}  // namespace
}  // namespace cellrt
