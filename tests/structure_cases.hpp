// The scenes every acceleration structure is held to: built-in scenes, the shared real scenes, and a
// catalogue of degenerate inputs (after Embree's verify suite).
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "cellrt/builtin.hpp"
#include "ray_suite.hpp"
#include "scenes.hpp"

namespace cellrt::test {

inline std::vector<std::string> structure_scene_names() {
    return {"builtin:spheres?tris=2000", "builtin:city?tris=20000", "builtin:forest?tris=20000",
            "teapot", "bunny", "sponza", "sibenik"};
}

// The scene for a name of structure_scene_names(); nullptr when a shared scene is absent.
inline const Scene* structure_scene(const std::string& name) {
    if (name.rfind("builtin:", 0) == 0) return &cached_scene(name);
    const std::string path = shared_view(name);
    return path.empty() ? nullptr : &cached_scene(path);
}

// A GoogleTest-friendly name: letters and digits only.
inline std::string test_name(const std::string& name) {
    std::string out;
    for (char c : name.substr(0, name.find('?'))) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    return out;
}

inline RaySuiteOptions small_suite() {
    RaySuiteOptions o;
    o.random = o.inside = o.vertices = o.edges = 4000;
    o.axis_parallel = 1200;
    o.planes = 3000;
    return o;
}

// 300 small random triangles (sides up to 0.2) in the unit cube at (3, 0, -2), all scaled by `scale`:
// off the origin by a few times its size, so that the distances from rays to it grow with the scale.
inline std::vector<Triangle> soup(float scale) {
    std::uint32_t state = 777;
    auto next = [&] { return float((state = state * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
    std::vector<Triangle> out;
    for (int i = 0; i < 300; ++i) {
        const Vec3 c = Vec3{next() + 3.f, next(), next() - 2.f}, e = Vec3{next(), next(), next()} * 0.2f;
        out.push_back({c * scale, (c + Vec3{e.x, 0.f, e.z}) * scale, (c + Vec3{0.f, e.y, e.x}) * scale});
    }
    return out;
}

// The unit soup beside triangles reaching +-3e38, where sums of coordinates overflow: the SAH BIH's
// centres were infinite (a box's lo + hi at x = 3e38) and its bins' conversion of NaN crashed it
// (bih@split=sah); and TA_rec's points at an end of the ray where the box's plane distance
// overflowed were NaN, which chose children at random (kd:rec, on rays unbounded behind:
// UnboundedBehind). Found by audit, 2026-12-07.
inline std::vector<Triangle> soup_at_the_range_edge() {
    std::vector<Triangle> out = soup(1.f);
    const float f = 3e38f;
    out.push_back({{f, f, f}, {-f, f, f}, {f, -f, -f}});
    out.push_back({{-f, -f, -f}, {f, -f, f}, {f, f, -f}});
    out.push_back({{f, 0.f, 0.f}, {f, 1.f, 0.f}, {f, 0.f, 1.f}});
    return out;
}

inline std::vector<std::pair<std::string, std::vector<Triangle>>> degenerate_scenes() {
    std::vector<std::pair<std::string, std::vector<Triangle>>> out;
    const Triangle unit{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}};
    out.push_back({"one triangle", {unit}});

    std::vector<Triangle> grid;  // coplanar, axis-aligned: a 20 x 20 grid of quads in y = 0
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j) {
            const float x = float(i), z = float(j);
            grid.push_back({{x, 0.f, z}, {x + 1.f, 0.f, z}, {x + 1.f, 0.f, z + 1.f}});
            grid.push_back({{x, 0.f, z}, {x + 1.f, 0.f, z + 1.f}, {x, 0.f, z + 1.f}});
        }
    out.push_back({"coplanar grid", grid});

    std::vector<Triangle> flat;  // flat in z: partly overlapping random triangles in the plane z = 1.5
    std::uint32_t state = 12345;
    auto next = [&] { return float((state = state * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
    for (int i = 0; i < 500; ++i) {
        const float x = next() * 10, y = next() * 10;
        flat.push_back({{x, y, 1.5f}, {x + next(), y + next(), 1.5f}, {x + next(), y - next(), 1.5f}});
    }
    out.push_back({"flat in z", flat});

    out.push_back({"duplicates", std::vector<Triangle>(1000, unit)});

    std::vector<Triangle> zero;  // zero-area triangles (points, lines, repeated vertices) among real ones
    for (int i = 0; i < 300; ++i) {
        const Vec3 p{next() * 4, next() * 4, next() * 4}, q{next() * 4, next() * 4, next() * 4};
        zero.push_back({p, p, p});
        zero.push_back({p, q, p});
        zero.push_back({p, (p + q) * 0.5f, q});
        zero.push_back({p, q, Vec3{next() * 4, next() * 4, next() * 4}});
    }
    out.push_back({"zero area", zero});

    // Slivers (12 long, some 1e-6 wide), whose float t strays along them by more than the margins,
    // and triangles of exactly zero area (collinear vertices on small integers) beside real ones,
    // which rounding gives a determinant: brute force took hits there that structures culled
    // (found by audit, 2026-12-07; triangle.hpp, ill_conditioned).
    std::vector<Triangle> slivers;
    for (int i = 0; i < 200; ++i) {
        const Vec3 a{next() * 4, next() * 4, next() * 4};
        const Vec3 b = a + Vec3{next() - 0.5f, next() - 0.5f, next() - 0.5f} * 12.f;
        const Vec3 c = a + (b - a) * next() + Vec3{next() - 0.5f, next() - 0.5f, next() - 0.5f} * 2e-6f;
        slivers.push_back({a, b, c});
    }
    out.push_back({"slivers", slivers});
    std::vector<Triangle> collinear;
    for (int i = 0; i < 200; ++i) {
        const Vec3 p{std::floor(next() * 8), std::floor(next() * 8), std::floor(next() * 8)};
        const Vec3 d{std::floor(next() * 5) - 2, std::floor(next() * 5) - 2, std::floor(next() * 5) - 2};
        collinear.push_back({p, p + d, p + d * 2.f});
        collinear.push_back({p + Vec3{0.25f, 0.f, 0.f}, p + d + Vec3{0.f, 0.5f, 0.f}, p + d * 2.f + Vec3{0.f, 0.f, 0.5f}});
    }
    out.push_back({"collinear", collinear});

    std::vector<Triangle> huge;  // tiny triangles near the origin and enormous ones far away
    for (int i = 0; i < 200; ++i) {
        const Vec3 c{next() * 1e-3f, next() * 1e-3f, next() * 1e-3f};
        huge.push_back({c, c + Vec3{1e-4f, 0.f, 0.f}, c + Vec3{0.f, 1e-4f, 1e-5f}});
        const Vec3 f{next() * 1e12f, next() * 1e12f, next() * 1e12f};
        huge.push_back({f, f + Vec3{1e11f, next() * 1e10f, 0.f}, f + Vec3{0.f, 1e11f, 1e11f}});
    }
    out.push_back({"huge coordinate range", huge});

    // Scenes whose lengths squared leave a float's range (traversal_margin's second branch), seen
    // along unit directions: at 1e20 the margin was inf / inf, NaN, and every structure culled the
    // whole scene; at 1e-17 the watertight test's T underflows, and its hits take t in double
    // precision (triangle.hpp, t_underflowed) within the margin's floor: every path must agree.
    // At 1e15 the determinant is a normal float (some 1e30) but T, a length cubed, overflows along
    // unit directions: t is +inf in front of the origin and -inf behind it, which the rays with
    // tnear = -inf (RaySuite::limited) would take but for the queries' finite bounds.
    out.push_back({"soup at 1e20", soup(1e20f)});
    out.push_back({"soup at 1e15", soup(1e15f)});
    out.push_back({"soup at 1e-17", soup(1e-17f)});
    out.push_back({"soup beside triangles at +-3e38", soup_at_the_range_edge()});
    return out;
}

}  // namespace cellrt::test
