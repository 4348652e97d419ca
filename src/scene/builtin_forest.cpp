// builtin:forest, the stand-in for the study's FFOREST scene: many small, detailed, irregular trees
// (a tapered trunk, cone branches, loose leaf triangles) scattered over hilly terrain. It stresses
// what the city does not: tiny triangles in dense clusters with empty space between them, triangles
// of very different sizes (terrain against leaves), and shadow rays that pass through gaps in the
// foliage.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "builtin_generators.hpp"
#include "mesh_builder.hpp"
#include "random.hpp"

namespace cellrt::detail {
namespace {

constexpr float kTreeSpacing = 3.5f;  // mean distance between neighbouring trees, metres
constexpr float kMargin = 2.f;        // no trunk closer than this to the terrain's edge

// A tree: a tapered trunk, branches (cones) along its upper part, twigs (thinner cones) off each
// branch, and loose leaf triangles in clusters at the top of the trunk and at every branch and twig tip.
constexpr int kTrunkSides = 6, kBranchSides = 5, kTwigSides = 4;
constexpr std::size_t kTrunkTris = MeshBuilder::frustum_triangles(kTrunkSides);
constexpr std::size_t kBranchTris = MeshBuilder::cone_triangles(kBranchSides);
constexpr std::size_t kTwigTris = MeshBuilder::cone_triangles(kTwigSides);
struct Range {  // inclusive, drawn uniformly
    int lo, hi;
    constexpr double mean() const { return 0.5 * (lo + hi); }
};
constexpr Range kBranches{3, 5};  // per tree
constexpr Range kTwigs{1, 3};     // per branch
constexpr Range kTopLeaves{20, 36}, kBranchLeaves{10, 18}, kTwigLeaves{6, 12};  // leaves per cluster
// The smallest tree, a trunk and one leaf: the last tree of a scene may be cut down to it.
constexpr std::size_t kMinTreeTris = kTrunkTris + 1;
constexpr double kMeanTreeTris =
    kTrunkTris + kTopLeaves.mean() +
    kBranches.mean() * (kBranchTris + kBranchLeaves.mean() + kTwigs.mean() * (kTwigTris + kTwigLeaves.mean()));

// Hills: value noise (random heights on a square lattice, smoothly interpolated), three octaves.
class Terrain {
public:
    Terrain(std::uint64_t seed, float half, int cells) : seed_(seed), half_(half), cells_(cells) {
        step_ = 2.f * half / static_cast<float>(cells);
        heights_.resize(static_cast<std::size_t>(cells + 1) * (cells + 1));
        for (int j = 0; j <= cells; ++j)
            for (int i = 0; i <= cells; ++i) heights_[index(i, j)] = noise(coordinate(i), coordinate(j));
    }

    Vec3 vertex(int i, int j) const { return {coordinate(i), stored(i, j), coordinate(j)}; }

    void build(MeshBuilder& mesh) const {
        for (int j = 0; j < cells_; ++j)
            for (int i = 0; i < cells_; ++i)
                mesh.quad(vertex(i, j), vertex(i, j + 1), vertex(i + 1, j + 1), vertex(i + 1, j));
    }

    // Height of the mesh itself (not of the noise) at (x, z): trees must stand on what is drawn.
    float height(float x, float z) const {
        const float gx = (x + half_) / step_, gz = (z + half_) / step_;
        const int i = std::clamp(static_cast<int>(gx), 0, cells_ - 1);
        const int j = std::clamp(static_cast<int>(gz), 0, cells_ - 1);
        const float fx = gx - static_cast<float>(i), fz = gz - static_cast<float>(j);
        // build() splits each cell along the diagonal from (i, j) to (i + 1, j + 1).
        const float h00 = stored(i, j), h11 = stored(i + 1, j + 1);
        if (fx >= fz) return h00 + fx * (stored(i + 1, j) - h00) + fz * (h11 - stored(i + 1, j));
        return h00 + fz * (stored(i, j + 1) - h00) + fx * (h11 - stored(i, j + 1));
    }

private:
    float coordinate(int i) const { return -half_ + step_ * static_cast<float>(i); }
    std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * (cells_ + 1) + i; }
    float stored(int i, int j) const { return heights_[index(i, j)]; }

    float octave(float x, float z, float wavelength, std::uint64_t salt) const {
        const float gx = x / wavelength, gz = z / wavelength;
        const float fx0 = std::floor(gx), fz0 = std::floor(gz);
        const auto i = static_cast<std::int64_t>(fx0), j = static_cast<std::int64_t>(fz0);
        auto smooth = [](float t) { return t * t * (3.f - 2.f * t); };
        const float sx = smooth(gx - fx0), sz = smooth(gz - fz0);
        const std::uint64_t s = seed_ ^ salt;
        const float a = lattice_value(s, i, j), b = lattice_value(s, i + 1, j);
        const float c = lattice_value(s, i, j + 1), d = lattice_value(s, i + 1, j + 1);
        return (a + (b - a) * sx) * (1.f - sz) + (c + (d - c) * sx) * sz;
    }

    float noise(float x, float z) const {
        return 6.f * octave(x, z, 45.f, 0x51) + 1.5f * octave(x, z, 13.f, 0x52) + 0.3f * octave(x, z, 3.f, 0x53);
    }

    std::uint64_t seed_;
    float half_, step_ = 1.f;
    int cells_;
    std::vector<float> heights_;
};

Vec3 random_in_ball(SplitMix64& rng) {
    for (;;) {
        const Vec3 v{rng.uniform(-1.f, 1.f), rng.uniform(-1.f, 1.f), rng.uniform(-1.f, 1.f)};
        if (dot(v, v) <= 1.f) return v;
    }
}

struct LeafCluster {
    Vec3 centre;
    float radius;
    int leaves;
};

// One tree standing at `ground`, of at most `budget` (>= kMinTreeTris) triangles. The solids come
// first, each only if it still fits with one leaf, then the leaves, cut to what is left: the last
// tree of a scene stays within the budget and no solid is ever cut open.
void tree(MeshBuilder& mesh, SplitMix64& rng, const Vec3& ground, std::size_t budget,
          std::vector<LeafCluster>& clusters) {
    const float height = rng.uniform(4.f, 7.f);
    const Vec3 base = ground - Vec3{0.f, 0.3f, 0.f};  // sunk a little: the ground is not flat under it
    const Vec3 top = base + Vec3{rng.uniform(-0.5f, 0.5f), height, rng.uniform(-0.5f, 0.5f)};
    const float radius = rng.uniform(0.12f, 0.2f);
    mesh.frustum(base, top, radius, 0.3f * radius, kTrunkSides);
    std::size_t used = kTrunkTris;
    clusters.assign(1, {top, 1.3f, rng.integer(kTopLeaves.lo, kTopLeaves.hi)});

    const int branches = rng.integer(kBranches.lo, kBranches.hi);
    const double turn = 2.0 * std::numbers::pi * rng.uniform();
    for (int b = 0; b < branches && used + kBranchTris + 1 <= budget; ++b) {
        const float along = rng.uniform(0.35f, 0.85f);
        const Vec3 start = base + (top - base) * along;
        const double azimuth = turn + 2.0 * std::numbers::pi * (b + 0.3 * rng.uniform(-1.f, 1.f)) / branches;
        const Vec3 dir = normalize({static_cast<float>(std::cos(azimuth)), rng.uniform(0.3f, 0.9f),
                                    static_cast<float>(std::sin(azimuth))});
        const float length = rng.uniform(1.2f, 2.2f) * (1.25f - 0.5f * along);
        const Vec3 tip = start + dir * length;
        mesh.cone(start, tip, 0.3f * radius, kBranchSides);
        used += kBranchTris;
        clusters.push_back({tip, 0.9f, rng.integer(kBranchLeaves.lo, kBranchLeaves.hi)});
        const int twigs = rng.integer(kTwigs.lo, kTwigs.hi);
        for (int t = 0; t < twigs && used + kTwigTris + 1 <= budget; ++t) {
            const Vec3 from = start + dir * (length * rng.uniform(0.35f, 0.8f));
            const Vec3 to = from + normalize(dir + random_in_ball(rng)) * rng.uniform(0.5f, 1.f);
            mesh.cone(from, to, 0.15f * radius, kTwigSides);
            used += kTwigTris;
            clusters.push_back({to, 0.6f, rng.integer(kTwigLeaves.lo, kTwigLeaves.hi)});
        }
    }

    for (const LeafCluster& c : clusters) {
        const auto leaves = std::min(static_cast<std::size_t>(c.leaves), budget - used);
        for (std::size_t k = 0; k < leaves; ++k) {
            const Vec3 at = c.centre + random_in_ball(rng) * c.radius;
            const float size = rng.uniform(0.3f, 0.55f);
            mesh.triangle(at, at + random_in_ball(rng) * size, at + random_in_ball(rng) * size);
        }
        used += leaves;
    }
}

}  // namespace

void make_forest(Scene& scene, const BuiltinParams& p) {
    const std::size_t budget = p.tris;
    // About a tenth of the budget for the terrain, the rest for trees at constant density, so that
    // a larger budget means a larger forest of the same trees.
    const int cells = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(budget) / 20.0)), 4, 1024);
    const std::size_t terrain_tris = 2 * static_cast<std::size_t>(cells) * cells;
    const double trees = std::max(1.0, static_cast<double>(budget - std::min(budget, terrain_tris)) / kMeanTreeTris);
    const float half = 0.5f * static_cast<float>(std::sqrt(trees)) * kTreeSpacing + kMargin;

    scene.triangles.reserve(budget);
    MeshBuilder mesh(scene.triangles);
    const Terrain terrain(p.seed, half, cells);
    terrain.build(mesh);

    // Trees at uniformly random places until the budget is spent.
    SplitMix64 rng(p.seed);
    std::vector<LeafCluster> clusters;
    while (scene.triangles.size() + kMinTreeTris <= budget) {
        const float x = rng.uniform(-half + kMargin, half - kMargin), z = rng.uniform(-half + kMargin, half - kMargin);
        tree(mesh, rng, {x, terrain.height(x, z), z}, budget - scene.triangles.size(), clusters);
    }

    // From above one side of the forest (or from inside a large one), looking down towards its centre.
    const float reach = std::min(half, 25.f);
    const Vec3 eye_ground{0.75f * reach, 0.f, 0.95f * reach};
    const float eye_height = terrain.height(eye_ground.x, eye_ground.z) + 6.f + 0.2f * reach;
    scene.camera.position = {eye_ground.x, eye_height, eye_ground.z};
    scene.camera.look_at = {0.f, terrain.height(0.f, 0.f) + 3.f, 0.f};
    scene.camera.up = {0.f, 1.f, 0.f};
    scene.camera.fov_y_deg = 55.f;
    scene.light.position = Vec3{-0.5f, 1.2f, 0.35f} * (half + 300.f);
    scene.light.color = {1.f, 1.f, 1.f};
}

}  // namespace cellrt::detail
