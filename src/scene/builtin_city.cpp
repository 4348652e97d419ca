// builtin:city, the stand-in for the study's CITY scene: square blocks of box buildings on a ground
// plane, streets between the blocks, tall towers downtown, seen from inside a street. Most of the
// scene hides behind the nearest buildings, so it stresses what an interior does: many occluders,
// short shadow rays in the streets, long rays down the street canyons.
#include <algorithm>
#include <cmath>
#include <vector>

#include "builtin_generators.hpp"
#include "mesh_builder.hpp"
#include "random.hpp"

namespace cellrt::detail {
namespace {

// Layout, in metres.
constexpr int kLotsPerSide = 3;        // a block is 3 x 3 building lots
constexpr float kLot = 12.f;
constexpr float kBlock = kLot * kLotsPerSide;
constexpr float kStreet = 14.f;        // kerb to kerb plus pavements
constexpr float kPavement = 2.5f;      // the block's kerb slab reaches this far into the street
constexpr float kPitch = kBlock + kStreet;
constexpr float kStorey = 3.2f;
constexpr float kDowntownRadius = 250.f;  // towers thin out over this distance from the centre (at most)

// A building is a podium, a tower set back on it and a roof unit (lift housing, water tank): three
// boxes, so a budget counts buildings exactly.
constexpr std::size_t kBuildingTris = 3 * MeshBuilder::kBoxTriangles;
constexpr std::size_t kSlabTris = MeshBuilder::kBoxTriangles;
constexpr std::size_t kGroundTris = 2;

// `downtown` is 1 at the city centre and falls towards 0 away from it: buildings grow taller towards it.
void building(MeshBuilder& mesh, SplitMix64& rng, float x0, float z0, float downtown) {
    const float u = rng.uniform();
    const int storeys = 2 + static_cast<int>(u * u * (4.f + 36.f * downtown * downtown));
    const float height = static_cast<float>(storeys) * kStorey;
    // Podium: the lot less a random margin on each side.
    const Vec3 lo{x0 + rng.uniform(0.6f, 2.5f), 0.f, z0 + rng.uniform(0.6f, 2.5f)};
    const Vec3 hi{x0 + kLot - rng.uniform(0.6f, 2.5f), height * rng.uniform(0.3f, 1.f),
                  z0 + kLot - rng.uniform(0.6f, 2.5f)};
    mesh.box(lo, hi);
    // Tower: inset by 10-25% of the podium on each side, up to the full height (at least one storey).
    const float wx = hi.x - lo.x, wz = hi.z - lo.z;
    const Vec3 tlo{lo.x + wx * rng.uniform(0.1f, 0.25f), hi.y, lo.z + wz * rng.uniform(0.1f, 0.25f)};
    const Vec3 thi{hi.x - wx * rng.uniform(0.1f, 0.25f), std::max(height, hi.y + kStorey),
                   hi.z - wz * rng.uniform(0.1f, 0.25f)};
    mesh.box(tlo, thi);
    // Roof unit: somewhere on the tower's roof.
    const float sx = std::min(thi.x - tlo.x, rng.uniform(1.f, 3.f));
    const float sz = std::min(thi.z - tlo.z, rng.uniform(1.f, 3.f));
    const float rx = tlo.x + (thi.x - tlo.x - sx) * rng.uniform(), rz = tlo.z + (thi.z - tlo.z - sz) * rng.uniform();
    mesh.box({rx, thi.y, rz}, {rx + sx, thi.y + rng.uniform(1.f, 3.f), rz + sz});
}

}  // namespace

void make_city(Scene& scene, const BuiltinParams& p) {
    const std::size_t budget = p.tris;
    // Blocks needed for the budget, on the smallest square grid that holds them; filled from the
    // centre outwards so that a city of any size is compact, with its downtown in the middle.
    const std::size_t full_block = kSlabTris + kLotsPerSide * kLotsPerSide * kBuildingTris;
    const std::size_t blocks = std::max<std::size_t>(1, (budget - kGroundTris + full_block - 1) / full_block);
    const int grid = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(blocks))));
    struct Cell {
        int i, j;
        long long key;  // squared distance from the grid centre, in half cells
    };
    std::vector<Cell> cells;
    cells.reserve(static_cast<std::size_t>(grid) * grid);
    for (int j = 0; j < grid; ++j)
        for (int i = 0; i < grid; ++i) {
            const long long di = 2 * i - (grid - 1), dj = 2 * j - (grid - 1);
            cells.push_back({i, j, di * di + dj * dj});
        }
    std::stable_sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });

    const float half = 0.5f * static_cast<float>(grid) * kPitch;  // the grid spans [-half, half]^2
    const float downtown_radius = std::min(kDowntownRadius, 0.5f * half);
    scene.triangles.reserve(budget);
    MeshBuilder mesh(scene.triangles);
    const float ground = half + kPitch;
    mesh.quad({-ground, 0.f, -ground}, {-ground, 0.f, ground}, {ground, 0.f, ground}, {ground, 0.f, -ground});

    SplitMix64 rng(p.seed);
    for (const Cell& c : cells) {
        if (scene.triangles.size() + kSlabTris + kBuildingTris > budget) break;
        const float bx = -half + kStreet * 0.5f + static_cast<float>(c.i) * kPitch;
        const float bz = -half + kStreet * 0.5f + static_cast<float>(c.j) * kPitch;
        mesh.box({bx - kPavement, 0.f, bz - kPavement}, {bx + kBlock + kPavement, 0.15f, bz + kBlock + kPavement});
        const float dx = bx + 0.5f * kBlock, dz = bz + 0.5f * kBlock;
        const float downtown = 1.f / (1.f + (dx * dx + dz * dz) / (downtown_radius * downtown_radius));
        for (int lot = 0; lot < kLotsPerSide * kLotsPerSide; ++lot) {
            if (scene.triangles.size() + kBuildingTris > budget) break;
            building(mesh, rng, bx + kLot * static_cast<float>(lot % kLotsPerSide),
                     bz + kLot * static_cast<float>(lot / kLotsPerSide), downtown);
        }
    }

    // The camera stands in a street near the centre line, at the edge of a small city or six blocks
    // out in a large one, and looks along it towards downtown. A city of one block has no street
    // through it (its one street is its edge, and the view along it looked away from the block: found
    // by audit, 2026-12-07): the camera looks at the block.
    const float street_x = -half + static_cast<float>(grid / 2) * kPitch;  // centre line of a street
    const float distance = std::min(half + 0.5f * kPitch, 6.f * kPitch);
    scene.camera.position = {street_x + 3.f, 22.f, distance};
    scene.camera.look_at = {grid > 1 ? street_x - 0.35f * distance : 0.f, grid > 1 ? 16.f : 8.f, 0.f};
    scene.camera.up = {0.f, 1.f, 0.f};
    scene.camera.fov_y_deg = 60.f;
    // A high, sun-like light from behind the camera's left: lit facades, shadows across the streets.
    scene.light.position = Vec3{-0.6f, 1.1f, 0.8f} * (half + 600.f);
    scene.light.color = {1.f, 1.f, 1.f};
}

}  // namespace cellrt::detail
