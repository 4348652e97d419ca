// builtin:spheres, the smallest scene with closed meshes, shadows and sky.
#include <algorithm>
#include <cmath>

#include "builtin_generators.hpp"
#include "mesh_builder.hpp"

namespace cellrt::detail {

// A row of spheres on a ground plane, with a box.
void make_spheres(Scene& scene, const BuiltinParams& p) {
    // Five spheres share the rest of the budget. A sphere of s segments and r rings has s * (2r - 2)
    // triangles; r follows from s ~ 2r, then s is fitted to the budget.
    constexpr int kSpheres = 5;
    const double fixed = 2 + MeshBuilder::kBoxTriangles;
    const double per_sphere = std::max(24.0, (static_cast<double>(p.tris) - fixed) / kSpheres);
    const int rings = std::max(2, static_cast<int>(std::lround(std::sqrt(per_sphere / 4.0))));
    const int segments = std::max(3, static_cast<int>(std::lround(per_sphere / (2 * rings - 2))));
    const std::size_t sphere_tris = static_cast<std::size_t>(segments) * static_cast<std::size_t>(2 * rings - 2);
    scene.triangles.reserve(static_cast<std::size_t>(fixed) + kSpheres * sphere_tris);
    MeshBuilder mesh(scene.triangles);
    mesh.quad({-6.f, 0.f, -6.f}, {-6.f, 0.f, 6.f}, {6.f, 0.f, 6.f}, {6.f, 0.f, -6.f});
    mesh.box({2.f, 0.f, -3.f}, {3.5f, 1.5f, -1.5f});
    for (int i = 0; i < kSpheres; ++i) {
        const float x = -4.f + 2.f * static_cast<float>(i);
        mesh.sphere({x, 0.8f, 1.f}, 0.8f, segments, rings);
    }
    scene.camera = {{0.f, 4.f, 9.f}, {0.f, 0.8f, 0.f}, {0.f, 1.f, 0.f}, 50.f};
    scene.light = {{-3.f, 8.f, 4.f}, {1.f, 1.f, 1.f}};
}

}  // namespace cellrt::detail
