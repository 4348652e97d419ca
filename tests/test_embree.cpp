// The Embree 3 backend against brute force. Embree runs its own triangle test (Pluecker with a small
// epsilon when robust, Moeller-Trumbore otherwise) and its own reciprocal, so its hits agree with
// cellrt's watertight test only up to rounding, and the comparison uses a tolerance:
//
// - Closest hit: both miss, or both hit at the same t up to rounding: kTolerance relative to t, plus
//   kTolerance of the scene's size divided by the cosine between ray and triangle (t inherits the
//   rounding of the coordinates, magnified for a ray that grazes the triangle's plane). The same t on
//   a different triangle is agreement when cellrt's test also hits Embree's triangle there: a tie
//   (a shared edge or vertex, overlapping triangles) that the two tests break differently.
// - Any other difference must be a close call, which rounding may decide either way: the hit (by
//   either test) lies within kMargin of the scene's size from an edge of its triangle (measured in
//   3D, in double precision, between the ray's line and the edge), or its t is within the t tolerance
//   of tnear or tfar (the suite's limited rays end exactly at the reference hit).
// - The full suite is largely made of close calls on purpose (rays aimed exactly at vertices and
//   edges, intervals ending exactly at hits): 5-9% of its rays differ, every one a close call (none
//   needs more than 1e-6 of the scene's size, so the margins above leave a factor of 10). On
//   generic rays (random origins and directions) at least 99.9% must also agree outright, closest hit
//   and occlusion alike; there a difference needs a ray through a silhouette edge or vertex, and none
//   occurs in the scenes tested.
#ifdef CELLRT_HAVE_EMBREE

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "ray_suite.hpp"
#include "scenes.hpp"

namespace cellrt {
namespace {

constexpr double kMargin = 1e-5;     // close call: this fraction of the scene's size from an edge
constexpr double kTolerance = 1e-5;  // same t: relative, and of the scene's size along the ray

AccelConfig embree_config(const std::string& traversal = "", std::map<std::string, std::string> params = {}) {
    AccelConfig c{"embree", traversal};
    c.params = std::move(params);
    return c;
}

struct Answers {
    std::vector<Hit> hits;
    std::vector<std::uint8_t> occluded;
};

// Answers in batches of varying size (1 to 300 rays), so that packet traversals also meet partial
// last chunks; batches run in parallel as the renderer runs them.
Answers answer(const Accelerator& accel, const std::vector<Ray>& rays) {
    Answers a{std::vector<Hit>(rays.size()), std::vector<std::uint8_t>(rays.size())};
    std::vector<std::size_t> starts;
    for (std::size_t s = 0, n = 1; s < rays.size(); s += n, n = n % 300 + 37) starts.push_back(s);
    starts.push_back(rays.size());
    const std::span<const Ray> all(rays);
    test::parallel_chunks(starts.size() - 1, 1, [&](std::size_t b, std::size_t) {
        const std::size_t s = starts[b], n = starts[b + 1] - starts[b];
        accel.intersect(all.subspan(s, n), std::span(a.hits).subspan(s, n));
        accel.occluded(all.subspan(s, n), std::span(a.occluded).subspan(s, n));
    });
    return a;
}

// Double-precision vector, for the distances that decide a close call.
struct DVec3 {
    double x, y, z;
    DVec3(const Vec3& v) : x(v.x), y(v.y), z(v.z) {}
    DVec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
    DVec3 operator-(const DVec3& b) const { return {x - b.x, y - b.y, z - b.z}; }
    DVec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    double dot(const DVec3& b) const { return x * b.x + y * b.y + z * b.z; }
    double length() const { return std::sqrt(dot(*this)); }
};

// Distance between the ray's line and the segment [a, b]: how far the ray must move for a test to
// see it cross that edge.
double distance_to_edge(const Ray& r, const Vec3& a, const Vec3& b) {
    const DVec3 d(r.dir);
    auto across = [&](const DVec3& x) { return x - d * (x.dot(d) / d.dot(d)); };  // x without its part along d
    const DVec3 w0 = across(DVec3(r.org) - DVec3(a)), e = across(DVec3(b) - DVec3(a));
    const double w = e.dot(e) > 0.0 ? std::clamp(w0.dot(e) / e.dot(e), 0.0, 1.0) : 0.0;
    return (w0 - e * w).length();
}

struct Comparison {
    std::span<const Triangle> tris;
    double size;  // the scene's diagonal

    // How far t may be off for a hit on triangle `prim` (see the file comment).
    double t_tolerance(const Ray& r, const Hit& h) const {
        const Vec3 n = tris[h.prim].geometric_normal();
        const double cosine = std::fabs(DVec3(n).dot(DVec3(r.dir))) / (DVec3(n).length() * DVec3(r.dir).length());
        return kTolerance * (std::fabs(h.t) + size / (DVec3(r.dir).length() * std::max(cosine, 1e-30)));
    }

    // Embree's hit `got` is the reference hit `want` up to rounding: the same t, and the same triangle
    // or one that cellrt's own test also finds at that t (a tie broken differently).
    bool same_closest(const Ray& r, const Hit& got, const Hit& want) const {
        if (got.is_hit() != want.is_hit()) return false;
        if (!got.is_hit()) return true;
        if (std::fabs(got.t - want.t) > std::max(t_tolerance(r, got), t_tolerance(r, want))) return false;
        float t, u, v;
        return got.prim == want.prim || (intersect_unbounded(WatertightRay(r), tris[got.prim], t, u, v) &&
                                         std::fabs(t - got.t) <= t_tolerance(r, got));
    }

    bool close_call(const Ray& r, const Hit& h) const {
        if (!h.is_hit()) return false;
        const Triangle& t = tris[h.prim];
        const double edge = std::min({distance_to_edge(r, t.v0, t.v1), distance_to_edge(r, t.v1, t.v2),
                                      distance_to_edge(r, t.v2, t.v0)});
        const double tol = t_tolerance(r, h);
        return edge <= kMargin * size || std::fabs(h.t - r.tnear) <= tol || std::fabs(r.tfar - h.t) <= tol;
    }
};

struct Differences {
    std::size_t closest = 0;      // rays whose closest hits differ
    std::size_t occlusion = 0;    // rays whose occlusion answers differ
    std::size_t unexplained = 0;  // of those, rays where no hit involved is a close call
};

// Embree against brute force on `rays`; reports the first few differences that are no close call.
Differences compare(const Accelerator& embree, std::span<const Triangle> tris, const std::vector<Ray>& rays,
                    const std::vector<Hit>& want_hits, const std::vector<std::uint8_t>& want_occluded,
                    const std::string& what) {
    Box3 bounds;
    for (const Triangle& t : tris) bounds.extend(t.bounds());
    const Comparison cmp{tris, DVec3(bounds.extent()).length()};
    const Answers got = answer(embree, rays);
    Differences diff;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Ray& r = rays[i];
        const Hit &want = want_hits[i], &hit = got.hits[i];
        const bool closest_agrees = cmp.same_closest(r, hit, want);
        const bool occlusion_agrees = got.occluded[i] == want_occluded[i];
        diff.closest += !closest_agrees;
        diff.occlusion += !occlusion_agrees;
        if ((closest_agrees && occlusion_agrees) || cmp.close_call(r, want) || cmp.close_call(r, hit)) continue;
        if (++diff.unexplained <= 5)
            ADD_FAILURE() << what << ": ray " << i << " " << test::describe(r) << "\n  closest: embree prim "
                          << hit.prim << " t " << hit.t << " (u " << hit.u << " v " << hit.v << "), brute prim "
                          << want.prim << " t " << want.t << " (u " << want.u << " v " << want.v
                          << ")\n  occluded: embree " << int(got.occluded[i]) << ", brute " << int(want_occluded[i]);
    }
    EXPECT_EQ(diff.unexplained, 0u) << what << ": differences from brute force that are no close call";
    return diff;
}

// The whole suite: every difference must be a close call.
void expect_suite_agrees(const Accelerator& embree, std::span<const Triangle> tris,
                         const test::ReferenceAnswers& ref, const std::string& what) {
    compare(embree, tris, ref.rays, ref.hits, ref.occluded, what + " (ray suite)");
}

// Generic rays (the suite's random, inside and axis-parallel rays, nothing aimed at a vertex or edge):
// at least 99.9% must agree outright. Their reference answers are computed once per scene.
void expect_generic_rays_agree(const Accelerator& embree, std::span<const Triangle> tris, const std::string& scene,
                               const std::string& what) {
    static std::map<std::string, test::ReferenceAnswers> cache;
    if (!cache.contains(scene)) {
        test::RaySuiteOptions generic;
        generic.vertices = generic.edges = generic.planes = 0;
        cache.emplace(scene, test::reference_suite(tris, generic, 0));
    }
    const test::ReferenceAnswers& ref = cache.at(scene);
    const Differences diff = compare(embree, tris, ref.rays, ref.hits, ref.occluded, what + " (generic rays)");
    EXPECT_LE(diff.closest, ref.rays.size() / 1000) << what << ": closest hits differ on " << diff.closest << " of "
                                                    << ref.rays.size() << " generic rays";
    EXPECT_LE(diff.occlusion, ref.rays.size() / 1000) << what << ": occlusion differs on " << diff.occlusion
                                                      << " of " << ref.rays.size() << " generic rays";
}

const std::string kSpheres = "builtin:spheres?tris=2000";

const char* const kTraversals[] = {"single", "packet4", "packet8", "packet16"};

// The traversals this machine offers.
std::vector<std::string> offered_traversals(std::span<const Triangle> tris) {
    std::vector<std::string> out;
    for (const char* t : kTraversals) {
        try {
            make_accelerator(tris, embree_config(t));
            out.emplace_back(t);
        } catch (const Error&) {
        }
    }
    return out;
}

TEST(Embree, AgreesWithBruteForceOnSpheres) {
    const Scene& scene = test::cached_scene(kSpheres);
    const auto embree = make_accelerator(scene.triangles, embree_config());
    expect_suite_agrees(*embree, scene.triangles, test::cached_reference(kSpheres, scene.triangles), "spheres");
    expect_generic_rays_agree(*embree, scene.triangles, kSpheres, "spheres");
}

TEST(Embree, EveryBuildVariantAgreesWithBruteForce) {
    const Scene& scene = test::cached_scene(kSpheres);
    const test::ReferenceAnswers& ref = test::cached_reference(kSpheres, scene.triangles);
    const std::map<std::string, std::string> variants[] = {
        {{"quality", "low"}}, {{"quality", "high"}}, {{"robust", "false"}}, {{"compact", "true"}},
        {{"robust", "false"}, {"compact", "true"}}};
    for (const auto& params : variants) {
        std::string what = "spheres,";
        for (const auto& [k, v] : params) what += " " + k + "=" + v;
        const auto embree = make_accelerator(scene.triangles, embree_config("", params));
        expect_suite_agrees(*embree, scene.triangles, ref, what);
        expect_generic_rays_agree(*embree, scene.triangles, kSpheres, what);
    }
}

TEST(Embree, AgreesWithBruteForceOnTeapot) {
    CELLRT_REQUIRE_SHARED_SCENE(path, "teapot");
    const Scene& scene = test::cached_scene(path);
    const auto embree = make_accelerator(scene.triangles, embree_config());
    expect_suite_agrees(*embree, scene.triangles, test::cached_reference(path, scene.triangles), "teapot");
    expect_generic_rays_agree(*embree, scene.triangles, path, "teapot");
}

// Packet traversals run Embree's packet kernels; on the same BVH they give the single-ray answers
// bit for bit (the ray-triangle arithmetic is the same per lane), including for partial last chunks.
TEST(Embree, PacketTraversalsGiveTheSingleRayAnswers) {
    const Scene& scene = test::cached_scene(kSpheres);
    const test::ReferenceAnswers& ref = test::cached_reference(kSpheres, scene.triangles);
    const auto single = make_accelerator(scene.triangles, embree_config("single"));
    const Answers want = answer(*single, ref.rays);
    const std::string native = single->stats().setting("native packets").value_or("");
    for (const char* width : {"4", "8", "16"}) {
        const std::string traversal = std::string("packet") + width;
        const bool offered = (',' + native + ',').find(std::string(",") + width + ",") != std::string::npos;
        if (!offered) {
            EXPECT_THROW(make_accelerator(scene.triangles, embree_config(traversal)), Error) << traversal;
            continue;
        }
        const auto packets = make_accelerator(scene.triangles, embree_config(traversal));
        const Answers got = answer(*packets, ref.rays);
        std::size_t differ = 0;
        for (std::size_t i = 0; i < ref.rays.size(); ++i)
            differ += std::memcmp(&got.hits[i], &want.hits[i], sizeof(Hit)) != 0 || got.occluded[i] != want.occluded[i];
        EXPECT_EQ(differ, 0u) << traversal << " differs from single on " << differ << " rays";
    }
}

TEST(Embree, SameAnswersAtOneBuildThreadAndAll) {
    const Scene& scene = test::cached_scene(kSpheres);
    const test::ReferenceAnswers& ref = test::cached_reference(kSpheres, scene.triangles);
    AccelConfig one = embree_config();
    one.threads = 1;
    const Answers a = answer(*make_accelerator(scene.triangles, one), ref.rays);
    const Answers b = answer(*make_accelerator(scene.triangles, embree_config()), ref.rays);
    EXPECT_EQ(std::memcmp(a.hits.data(), b.hits.data(), a.hits.size() * sizeof(Hit)), 0);
    EXPECT_EQ(a.occluded, b.occluded);
}

TEST(Embree, HitRecordUsesCellrtBarycentricsAndIndices) {
    // Zero-area triangles (a point, a line) before the real one must keep the indices of the input.
    const std::vector<Triangle> tris{{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}},
                                     {{-1.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}},
                                     {{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}}};
    Ray ray;
    ray.org = {0.25f, 0.5f, 2.f};
    ray.dir = {0.f, 0.f, -1.f};
    for (const std::string& t : offered_traversals(tris)) {
        const auto embree = make_accelerator(tris, embree_config(t));
        Hit h;
        std::uint8_t occ = 0;
        embree->intersect(std::span(&ray, 1), std::span(&h, 1));
        embree->occluded(std::span(&ray, 1), std::span(&occ, 1));
        EXPECT_EQ(h.prim, 2u) << t;
        EXPECT_FLOAT_EQ(h.t, 2.f) << t;
        EXPECT_FLOAT_EQ(h.u, 0.25f) << t << ": u weighs v1";
        EXPECT_FLOAT_EQ(h.v, 0.5f) << t << ": v weighs v2";
        EXPECT_EQ(occ, 1) << t;
    }
}

TEST(Embree, InvalidRaysMissOnEveryTraversal) {
    const Triangle tri{{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {0.f, 1.f, 0.f}};
    const float nan = std::nanf("");
    const Ray good{{0.f, 0.f, 1.f}, 0.f, {0.f, 0.f, -1.f}, kInfinity};
    const std::vector<Ray> invalid{Ray{{0.f, 0.f, 1.f}, 0.f, {0.f, 0.f, 0.f}, kInfinity},
                                   Ray{{0.f, 0.f, 1.f}, 0.f, {nan, 0.f, -1.f}, kInfinity},
                                   Ray{{nan, 0.f, 1.f}, 0.f, {0.f, 0.f, -1.f}, kInfinity},
                                   Ray{{kInfinity, 0.f, 1.f}, 0.f, {0.f, 0.f, -1.f}, kInfinity},
                                   Ray{{0.f, 0.f, 1.f}, 0.f, {0.f, kInfinity, -1.f}, kInfinity},
                                   Ray{{0.f, 0.f, 1.f}, 2.f, {0.f, 0.f, -1.f}, 1.f},
                                   Ray{{0.f, 0.f, 1.f}, nan, {0.f, 0.f, -1.f}, kInfinity},
                                   Ray{{0.f, 0.f, 1.f}, 0.f, {0.f, 0.f, -1.f}, nan}};
    // Invalid rays between valid ones, in a batch that is no multiple of any packet width.
    std::vector<Ray> rays;
    for (const Ray& r : invalid) {
        rays.push_back(good);
        rays.push_back(r);
    }
    rays.push_back(good);
    for (const std::string& t : offered_traversals(std::span(&tri, 1))) {
        const auto embree = make_accelerator(std::span(&tri, 1), embree_config(t));
        std::vector<Hit> hits(rays.size());
        std::vector<std::uint8_t> occ(rays.size(), 7);
        embree->intersect(rays, hits);
        embree->occluded(rays, occ);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const bool valid = i % 2 == 0;
            EXPECT_EQ(hits[i].is_hit(), valid) << t << " ray " << i;
            EXPECT_EQ(occ[i], valid ? 1 : 0) << t << " ray " << i;
            if (!valid) {
                EXPECT_EQ(hits[i], Hit{}) << t << " ray " << i;
            }
        }
    }
}

// Valid rays that Embree cannot take (it asserts on them) are refused with a message, never passed on.
TEST(Embree, RaysOutsideEmbreesDomainAreRefused) {
    const Triangle tri{{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {0.f, 1.f, 0.f}};
    const Ray behind{{0.f, 0.f, 1.f}, -1.f, {0.f, 0.f, 1.f}, kInfinity};
    const Ray huge{{0.f, 0.f, 1e30f}, 0.f, {0.f, 0.f, -1.f}, kInfinity};
    for (const std::string& t : offered_traversals(std::span(&tri, 1))) {
        const auto embree = make_accelerator(std::span(&tri, 1), embree_config(t));
        for (const Ray& r : {behind, huge}) {
            Hit h;
            std::uint8_t occ = 0;
            EXPECT_THROW(embree->intersect(std::span(&r, 1), std::span(&h, 1)), Error) << t;
            EXPECT_THROW(embree->occluded(std::span(&r, 1), std::span(&occ, 1)), Error) << t;
        }
    }
    const Triangle far_away{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1e30f, 0.f}};
    EXPECT_THROW(make_accelerator(std::span(&far_away, 1), embree_config()), Error);
}

// Embree picks its own instruction set, but a SIMD set named for it is one of the names, as for
// every other kind ("embree+banana" was taken and printed back).
TEST(Embree, ASimdSetNamedForItIsChecked) {
    const Triangle tri{{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {0.f, 1.f, 0.f}};
    AccelConfig config = embree_config();
    for (const std::string simd : {"auto", "off", "portable"}) {
        config.simd = simd;
        EXPECT_NO_THROW(make_accelerator(std::span(&tri, 1), config)) << simd;
    }
    for (const std::string simd : {"banana", "AVX2", ""}) {
        config.simd = simd;
        try {
            make_accelerator(std::span(&tri, 1), config);
            ADD_FAILURE() << "'" << simd << "' taken";
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()),
                      "SIMD instruction set '" + simd + "' is not one of: auto, off, portable, sse, avx2, avx512");
        }
    }
}

// A height field of quads split into triangles that share vertices exactly, and rays from above aimed
// at points of its inner edges and at its inner vertices: each ray must hit it. Embree's robust
// Pluecker test evaluates a shared edge identically for both triangles, so no ray through an edge
// leaks; at a vertex its per-edge epsilon is not exact, and a few of these rays (0.2% here) pass
// between the triangles. The Moeller-Trumbore test of robust=false leaks through edges as well.
TEST(Embree, RobustBuildDoesNotLeakThroughSharedEdges) {
    std::vector<Triangle> field;
    const int n = 40;
    auto p = [](int i, int j) { return Vec3{0.1f * i - 2.f, 0.01f * ((7 * i + 13 * j) % 5), 0.1f * j - 2.f}; };
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            field.push_back({p(i, j), p(i + 1, j), p(i + 1, j + 1)});
            field.push_back({p(i, j), p(i + 1, j + 1), p(i, j + 1)});
        }
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.f, 1.f), s(0.01f, 0.99f);
    std::uniform_int_distribution<int> cell(1, n - 1);
    std::vector<Ray> edge_rays, vertex_rays;
    for (int k = 0; k < 30000; ++k) {
        const int i = cell(rng), j = cell(rng);
        const Vec3 a = p(i, j), b = k % 3 == 1 ? p(i + 1, j) : p(i + 1, j + 1);  // along x, or the diagonal
        const Vec3 target = k % 3 == 0 ? a : a + (b - a) * s(rng);
        Ray r;
        r.org = target + Vec3{u(rng), 1.5f, u(rng)};
        r.dir = target - r.org;
        (k % 3 == 0 ? vertex_rays : edge_rays).push_back(r);
    }
    auto leaks = [](const Accelerator& accel, const std::vector<Ray>& rays) {
        const Answers got = answer(accel, rays);
        std::size_t n = 0;
        for (std::size_t k = 0; k < rays.size(); ++k) n += !got.hits[k].is_hit() || !got.occluded[k];
        return n;
    };
    for (const std::string& t : offered_traversals(field)) {
        const auto robust = make_accelerator(field, embree_config(t));
        EXPECT_EQ(leaks(*robust, edge_rays), 0u) << t << ": rays through shared edges passed between triangles";
        EXPECT_LE(leaks(*robust, vertex_rays), vertex_rays.size() / 100) << t;
        const auto fast = make_accelerator(field, embree_config(t, {{"robust", "false"}}));
        EXPECT_GT(leaks(*fast, edge_rays), 0u) << t << ": robust=false should run the Moeller-Trumbore test";
    }
}

TEST(Embree, EmptySceneAnswersMisses) {
    const std::vector<Triangle> none;
    const Ray ray{{0.f, 0.f, 1.f}, 0.f, {0.f, 0.f, -1.f}, kInfinity};
    for (const std::string& t : offered_traversals(none)) {
        const auto embree = make_accelerator(none, embree_config(t));
        Hit h{1.f, 3u, 0.5f, 0.5f};
        std::uint8_t occ = 1;
        embree->intersect(std::span(&ray, 1), std::span(&h, 1));
        embree->occluded(std::span(&ray, 1), std::span(&occ, 1));
        EXPECT_EQ(h, Hit{}) << t;
        EXPECT_EQ(occ, 0) << t;
    }
}

TEST(Embree, CountsRaysOnlyAndReportsItsBuild) {
    const Scene& scene = test::cached_scene(kSpheres);
    AccelConfig config = embree_config("", {{"quality", "high"}, {"robust", "false"}});
    config.threads = 1;
    const auto embree = make_accelerator(scene.triangles, config);
    std::vector<Ray> rays(100, Ray{scene.bounds().center(), 0.f, {0.f, 1.f, 0.f}, kInfinity});
    std::vector<Hit> hits(rays.size());
    std::vector<std::uint8_t> occ(rays.size());
    TraversalCounters counters;
    embree->intersect(rays, hits, &counters);
    embree->occluded(rays, occ, &counters);
    EXPECT_EQ(counters.rays, 200u);
    EXPECT_EQ(counters.nodes + counters.leaves + counters.triangles, 0u);

    const AccelStats stats = embree->stats();
    EXPECT_EQ(stats.name, "embree");
    EXPECT_GT(stats.build_seconds, 0.0);
    // At least the vertex and index buffers (48 bytes per triangle) plus a BVH.
    EXPECT_GT(stats.memory_bytes, 48 * scene.triangles.size());
    EXPECT_EQ(stats.setting("quality"), "high");
    EXPECT_EQ(stats.setting("robust"), "false");
    EXPECT_EQ(stats.setting("compact"), "false");
    EXPECT_EQ(stats.setting("threads"), "1");
    EXPECT_EQ(stats.traversal, "single");
    EXPECT_EQ(stats.triangles, scene.triangles.size());
    // Its zeros are not measured work: cellrt_bench prints "–" and cellrt profile "n/a" for them.
    EXPECT_FALSE(stats.counts_work);
    EXPECT_TRUE(make_accelerator(scene.triangles, {.kind = "kd"})->stats().counts_work);
}

TEST(Embree, RejectsBadParametersAndTraversals) {
    const Scene& scene = test::cached_scene(kSpheres);
    const std::map<std::string, std::string> bad[] = {
        {{"quality", "ultra"}}, {{"quality", ""}}, {{"robust", "maybe"}}, {{"compact", "2"}}, {{"leaf", "4"}}};
    for (const auto& params : bad)
        EXPECT_THROW(make_accelerator(scene.triangles, embree_config("", params)), Error) << params.begin()->first;
    for (const char* traversal : {"packet2", "packet32", "stream", "Single"})
        EXPECT_THROW(make_accelerator(scene.triangles, embree_config(traversal)), Error) << traversal;
    try {
        make_accelerator(scene.triangles, embree_config("", {{"quality", "ultra"}}));
        ADD_FAILURE() << "quality=ultra accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("quality"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace cellrt

#endif  // CELLRT_HAVE_EMBREE
