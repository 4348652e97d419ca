// Every acceleration structure and traversal returns exactly the brute-force hits (closest hit: t,
// triangle and barycentrics; any hit) on the ray suite of ray_suite.hpp, on built-in scenes, the
// shared real scenes and a catalogue of degenerate inputs; and every path that traces rays takes
// misuse (spans of different lengths, non-finite vertices, an empty scene, invalid rays, many threads
// at once) as accelerator.hpp and accel.hpp say.
#include <gtest/gtest.h>

#include <barrier>
#include <cmath>
#include <cstdint>
#include <functional>
#include <thread>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "accel/local_store_registry.hpp"
#include "error_of.hpp"
#include "ray_suite.hpp"
#include "simd/isa.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

// Every exact structure path: KIND:TRAVERSAL for single rays, KIND+SIMD for the packet kernels of
// each instruction set this machine runs (for the wide BVH, its single-ray, paired, stream and packet kernels
// of that set); and the BIH built with the SAH, by both.
std::vector<std::string> exact_configs() {
    std::vector<std::string> out = {"kd:rec", "kd:branched", "kd:branchless", "bih:branched", "bih:branchless",
                                    "bih:branched@split=sah", "bih+auto@split=sah", "auto", "auto@packets=bih",
                                    "auto@packets=bih-sah", "auto@packets=bvh", "auto@route=coherence", "auto@streams=off", "bvh:wide",
                                    "bvh:paired", "bvh:stream", "bvh:packet"};
    for (detail::Isa isa : detail::available_isas())
        for (const char* kind : {"kd", "bih", "bvh", "bvh:wide", "bvh:paired", "bvh:stream", "bvh:packet"})
            out.push_back(std::string(kind) + "+" + detail::to_string(isa));
    return out;
}
const std::vector<std::string> kConfigs = exact_configs();

// A GoogleTest name for a configuration: every character other than a letter or digit becomes '_'.
std::string name_of(const std::string& config) {
    std::string s = config;
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return s;
}

class AgainstBruteForce : public testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(AgainstBruteForce, SameHits) {
    const auto& [scene_name, config] = GetParam();
    const Scene* scene = test::structure_scene(scene_name);
    if (!scene) GTEST_SKIP() << "scene " << scene_name << " not found under " << test::scenes_dir();
    const test::ReferenceAnswers& ref = test::cached_reference(scene_name, scene->triangles);
    const auto accel = make_accelerator(scene->triangles, parse_accel_config(config));
    test::expect_matches(*accel, ref, config + " on " + scene_name);
}

INSTANTIATE_TEST_SUITE_P(Scenes, AgainstBruteForce,
                         testing::Combine(testing::ValuesIn(test::structure_scene_names()), testing::ValuesIn(kConfigs)),
                         [](const auto& info) {
                             return test::test_name(std::get<0>(info.param)) + "_" + name_of(std::get<1>(info.param));
                         });

class DegenerateInputs : public testing::TestWithParam<std::string> {};

TEST_P(DegenerateInputs, SameHits) {
    for (const auto& [name, tris] : test::degenerate_scenes()) {
        const test::ReferenceAnswers ref = test::stored_suite(tris, test::small_suite());
        test::expect_matches(*make_accelerator(tris, parse_accel_config(GetParam())), ref, GetParam() + " on " + name);
    }
}

INSTANTIATE_TEST_SUITE_P(Structures, DegenerateInputs, testing::ValuesIn(kConfigs),
                         [](const auto& info) { return name_of(info.param); });

// The suite's rays unbounded behind their origins (tnear = -inf) over the soups whose T overflows
// (1e15: t = -inf behind the origin along unit directions, with a normal determinant) or whose
// determinant does (1e20), and over the unit soup beside triangles at +-3e38
// (soup_at_the_range_edge): brute force's scalar test refuses a t that is not finite, and a SIMD
// kernel that leaves that to the query's bounds must find them finite (kernel/traversal.hpp,
// finite_tnear; with it taken out, `bvh:wide` takes the t = -inf hits).
class UnboundedBehind : public testing::TestWithParam<std::string> {};

TEST_P(UnboundedBehind, SameHits) {
    struct Case {
        const char* name;
        std::vector<Triangle> tris;
        test::ReferenceAnswers ref;
    };
    static const std::vector<Case> cases = [] {
        std::vector<Case> out;
        for (const auto& [name, scale] : {std::pair{"1e15", 1e15f}, std::pair{"1e20", 1e20f}, std::pair{"1 beside +-3e38", 0.f}}) {
            std::vector<Triangle> tris = scale == 0.f ? test::soup_at_the_range_edge() : test::soup(scale);
            std::vector<Ray> rays = test::RaySuite(tris, test::small_suite()).rays();
            if (scale == 0.f) {
                // Rays with a -0 component whose exit from the scene box overflows (the plane at 3e38
                // over a component of 0.54), each through a soup triangle's centre 7 units behind its
                // origin: TA_rec's exit point was inf * -0 = NaN there, and it missed them.
                const Vec3 d{-0.f, 0.54f, 0.074f};
                for (std::size_t i = 0; i < 50; ++i) {
                    const Vec3 centre = (tris[i].v0 + tris[i].v1 + tris[i].v2) * (1.f / 3.f);
                    rays.push_back(Ray{centre + d * 7.f, 0.f, d, kInfinity});
                }
            }
            for (Ray& r : rays) r.tnear = -kInfinity;
            test::ReferenceAnswers ref = test::compute_reference(tris, std::move(rays));
            out.push_back({name, std::move(tris), std::move(ref)});
        }
        return out;
    }();
    for (const Case& c : cases)
        test::expect_matches(*make_accelerator(c.tris, parse_accel_config(GetParam())), c.ref,
                             GetParam() + " on the soup at " + c.name + ", tnear = -inf");
}

INSTANTIATE_TEST_SUITE_P(Structures, UnboundedBehind, testing::ValuesIn(kConfigs),
                         [](const auto& info) { return name_of(info.param); });

// Directions with a component below 2^-126 beside a normal one (valid rays): its reciprocal
// overflows below about 2.9e-39, and every structure missed the first strip below, 1e-36 to 1e-34
// off the axis, which brute force hit (review, 2026-12-06). Every path now traces such a component
// as a zero of its sign (ray.hpp, traced_direction), brute force too, so all miss the strips.
// Components of 5e-39 and 1e-38 have finite reciprocals: a path that traced them unflushed would
// reach the second strip, 2e-34 to 2e-32 off the axis, where the reference misses. Components just
// above 2^-126 reach it on every path.
class SubnormalDirectionComponents : public testing::TestWithParam<std::string> {};

TEST_P(SubnormalDirectionComponents, SameHits) {
    static const auto scene = [] {
        // Strips across the x axis at x = +-1.5e5, off it in y or z by [lo, hi] on either side.
        std::vector<Triangle> tris;
        const auto strip = [&](float x, int axis, float lo, float hi) {
            const auto at = [&](float off, float across) {
                Vec3 p{x, 0.f, 0.f};
                p[axis] = off;
                p[3 - axis] = across;
                return p;
            };
            tris.push_back({at(lo, -1.f), at(hi, -1.f), at(hi, 1.f)});
            tris.push_back({at(lo, -1.f), at(hi, 1.f), at(lo, 1.f)});
        };
        for (const float x : {1.5e5f, -1.5e5f})
            for (int axis : {1, 2})
                for (const float side : {1.f, -1.f}) {
                    strip(x, axis, side * 1e-36f, side * 1e-34f);
                    strip(x, axis, side * 2e-34f, side * 2e-32f);
                }
        std::vector<Ray> rays;
        for (const float along : {1.f, -1.f, 3.f})
            for (const float s : {3e-40f, 1e-39f, 1e-45f, 5e-39f, 1e-38f, 1.2e-38f, 2e-38f, 5e-38f})
                for (const float sign : {1.f, -1.f})
                    for (int axis : {1, 2}) {
                        Ray r;
                        r.dir = {along, 0.f, 0.f};
                        r.dir[axis] = sign * s;
                        rays.push_back(r);
                    }
        return std::pair{tris, test::compute_reference(tris, std::move(rays))};
    }();
    const auto& [tris, ref] = scene;
    for (std::size_t i = 0; i < ref.rays.size(); ++i) {
        const float s = std::max(std::fabs(ref.rays[i].dir.y), std::fabs(ref.rays[i].dir.z));
        if (s < kLeastNormal) EXPECT_FALSE(ref.hits[i].is_hit()) << "brute force traces ray " << i << "'s component as 0";
        else EXPECT_TRUE(ref.hits[i].is_hit()) << "ray " << i << "'s normal component reaches the second strip";
    }
    test::expect_matches(*make_accelerator(tris, AccelConfig{"brute"}), ref, "the scalar brute force");
    test::expect_matches(*make_accelerator(tris, parse_accel_config(GetParam())), ref,
                         GetParam() + " on directions with subnormal components");
}

INSTANTIATE_TEST_SUITE_P(Structures, SubnormalDirectionComponents, testing::ValuesIn(kConfigs),
                         [](const auto& info) { return name_of(info.param); });

// A scene and its (valid) rays scaled by a power of two, vertices, origins and directions alike:
// every step of the watertight test scales exactly, so brute force finds the unscaled hits (triangle
// and t; the barycentrics can differ where an edge function leaves the normal range, and t where T
// overflows), and every structure must give brute force's answers. At 2^64 the squared distances
// from the origins to the scene overflow a float (up to 8.8 * 2^128) while the triangles' edge
// functions do not: the direct margin was inf / inf, NaN, and every structure culled the whole
// scene (fuzz_gltf found a glTF scene at 8.4e18); traversal_margin's second branch. At 2^-52 the
// squares are near 2^-104, still normal: every value small, nothing else. At 2^-46 with the
// directions unscaled, t scales by 2^-46 and the test's T, a length cubed, is subnormal (the edge
// functions stay normal); such hits are taken again in double precision (triangle.hpp,
// t_underflowed), so brute force finds the unscaled triangles at t within rounding of the scaled.
class ScaledByPowersOfTwo : public testing::TestWithParam<std::string> {};

TEST_P(ScaledByPowersOfTwo, SameHits) {
    struct Case {
        int exponent;
        bool directions;  // scaled too (t unchanged), or left alone (t scaled)
        std::vector<Triangle> tris;
        test::ReferenceAnswers ref;
    };
    static const auto [base, cases] = [] {
        const std::vector<Triangle> tris = test::soup(1.f);
        test::ReferenceAnswers unscaled =
            test::compute_reference(tris, test::RaySuite(tris, test::small_suite()).rays());
        std::vector<Case> out;
        for (const auto& [e, directions] : {std::pair{64, true}, std::pair{-52, true}, std::pair{-46, false}}) {
            const float s = std::ldexp(1.f, e);
            std::vector<Ray> rays = unscaled.rays;
            for (Ray& r : rays) {
                if (!is_valid(r)) continue;
                r.org = r.org * s;
                if (directions) r.dir = r.dir * s;
                else r.tnear *= s, r.tfar *= s;
            }
            std::vector<Triangle> scaled = test::soup(s);
            test::ReferenceAnswers ref = test::compute_reference(scaled, std::move(rays));
            out.push_back({e, directions, std::move(scaled), std::move(ref)});
        }
        return std::pair{std::move(unscaled), std::move(out)};
    }();
    for (const Case& c : cases) {
        const std::string what = GetParam() + " on a soup scaled by 2^" + std::to_string(c.exponent) +
                                 (c.directions ? "" : ", directions unscaled");
        std::size_t differ = 0, hits = 0;
        for (std::size_t i = 0; i < base.hits.size(); ++i) {
            const Hit& got = c.ref.hits[i];
            const Hit& want = base.hits[i];
            if (c.directions) {
                differ += got.prim != want.prim || !(got.t == want.t);
            } else {  // t within rounding of the scaled t: double precision where T underflowed
                const float scaled_t = std::ldexp(want.t, c.exponent);
                differ += got.prim != want.prim ||
                          (want.is_hit() && !(std::fabs(got.t - scaled_t) <= 1e-5f * std::fabs(scaled_t)));
            }
            hits += want.is_hit();
        }
        ASSERT_GT(hits, base.hits.size() / 10) << "the suite must meet the scene";
        EXPECT_LE(differ, base.hits.size() / 1000) << "brute force, " << what << ", against the unscaled soup";
        test::expect_matches(*make_accelerator(c.tris, parse_accel_config(GetParam())), c.ref, what);
    }
}

INSTANTIATE_TEST_SUITE_P(Structures, ScaledByPowersOfTwo, testing::ValuesIn(kConfigs),
                         [](const auto& info) { return name_of(info.param); });

// Rays nearly parallel to triangles that lie in axis planes, aimed at their vertices along their
// edges (found by audit, 2026-12-07): the refined t of such an ill-conditioned hit is the depth of
// the triangle's point nearest the ray, within rounding of the ray in space, but the ray crosses the
// plane by only its small direction component per unit of t, so that depth lay up to 3.5e-5
// (relative) from the plane's, past a margin in t (2^-16 of the scene's reach), and every structure
// culled a box or cell without thickness there that brute force's hit lies in. The margins of an
// axis' planes are in space (kernel/traversal.hpp, axis_margin). One triangle of the audit, and
// 6 x 6 grids in a plane of each axis (vertices at sixths); from either side of the plane, unbounded
// and again limited at brute force's hits (RaySuite::limited: tfar at t and an ulp before, tnear at
// t and an ulp after).
class GrazingAxisPlanes : public testing::TestWithParam<std::string> {};

TEST_P(GrazingAxisPlanes, SameHits) {
    struct Case {
        const char* name;
        std::vector<Triangle> tris;
        test::ReferenceAnswers ref;
    };
    static const std::vector<Case> cases = [] {
        // A point of the plane of axis `a` at `level`, with in-plane coordinates (p, q).
        const auto at = [](int a, float level, float p, float q) {
            Vec3 v;
            v[a] = level;
            v[(a + 1) % 3] = p;
            v[(a + 2) % 3] = q;
            return v;
        };
        std::vector<Triangle> grids;
        for (int a = 0; a < 3; ++a) {
            const float level = a == 0 ? 0.f : (a == 1 ? 2.f / 3.f : -1.3f);
            for (int i = 0; i < 6; ++i)
                for (int j = 0; j < 6; ++j) {
                    const float p0 = float(i) / 6.f, p1 = float(i + 1) / 6.f, q0 = float(j) / 6.f, q1 = float(j + 1) / 6.f;
                    grids.push_back({at(a, level, p0, q0), at(a, level, p1, q0), at(a, level, p1, q1)});
                    grids.push_back({at(a, level, p0, q0), at(a, level, p1, q1), at(a, level, p0, q1)});
                }
        }
        std::uint32_t state = 2026;
        const auto next = [&] { return float((state = state * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
        // Toward every vertex of every triangle along each of its two edges there (one way or the
        // other, at random), with a component across the plane of 0.5 to 1.5 times 1e-2 to 1e-7 of
        // the in-plane one, from either side.
        const auto grazing_rays = [&](const std::vector<Triangle>& tris) {
            std::vector<Ray> rays;
            for (const Triangle& t : tris) {
                const Vec3 v[3] = {t.v0, t.v1, t.v2};
                const Vec3 n = cross(t.v1 - t.v0, t.v2 - t.v0);
                const int a = std::fabs(n.x) > 0.f ? 0 : (std::fabs(n.y) > 0.f ? 1 : 2);
                for (int k = 0; k < 3; ++k)
                    for (int e = 1; e <= 2; ++e)
                        for (const float across : {1e-2f, 1e-3f, 5.9e-5f, 1e-5f, 1e-6f, 1e-7f})
                            for (const float side : {1.f, -1.f}) {
                                const float way = next() < 0.5f ? 1.f : -1.f;
                                Vec3 d = (v[(k + e) % 3] - v[k]) * way;
                                d[a] = side * across * length(d) * (0.5f + next());
                                const float reach = 0.5f + 2.f * next();
                                rays.push_back(Ray{v[k] - d * reach, 0.f, d, kInfinity});
                            }
            }
            return rays;
        };
        std::vector<Case> out;
        const std::vector<Triangle> one = {{{0.f, 0.f, 0.f}, {0.f, 0.f, 1.f}, {0.f, 1.f, 1.f}}};
        for (auto& [name, tris] : {std::pair{"one triangle in x = 0", one}, std::pair{"grids in three axis planes", grids}}) {
            out.push_back({name, tris,
                           test::with_limited(tris, test::compute_reference(tris, grazing_rays(tris)), SIZE_MAX)});
        }
        return out;
    }();
    for (const Case& c : cases) {
        std::size_t hits = 0;
        for (const Hit& h : c.ref.hits) hits += h.is_hit();
        ASSERT_GT(hits, c.ref.hits.size() / 4) << "the rays must meet " << c.name;
        test::expect_matches(*make_accelerator(c.tris, parse_accel_config(GetParam())), c.ref,
                             GetParam() + " on " + c.name + ", grazing rays");
    }
}

INSTANTIATE_TEST_SUITE_P(Structures, GrazingAxisPlanes, testing::ValuesIn(kConfigs),
                         [](const auto& info) { return name_of(info.param); });

// A triangle some 1e-16 across, 1e-16 behind origins that look away from it along unit directions,
// and a large one in front. The test's T, a length cubed, underflowed to zero and lost its sign: the
// tiny triangle was hit at t = -0, which tnear = 0 admits, on every path and Embree's too (found by
// audit, 2026-12-07). Rays looking the other way meet it in front, at t > 0.
TEST(Structures, ATinyTriangleJustBehindTheOriginIsNotHit) {
    for (const float s : {1e-16f, 1e-17f, 1e-18f}) {
        const std::vector<Triangle> tris = {{{-s, -s, -s}, {3 * s, -s, -s}, {-s, 3 * s, -s}},
                                            {{-5.f, -5.f, 1.f}, {5.f, -5.f, 1.f}, {0.f, 5.f, 1.f}}};
        std::vector<Ray> rays;
        for (int i = 0; i < 64; ++i) {
            Ray r;
            r.org = {s * 0.1f * float(i % 8), s * 0.1f * float(i / 8), 0.f};
            r.dir = {0.3f, 0.1f, i % 2 ? 1.f : -1.f};
            if (i % 4 == 1) r.tfar = 0.5f;  // looking up, short of the large triangle: not occluded
            rays.push_back(r);
        }
        const test::ReferenceAnswers ref = test::compute_reference(tris, std::move(rays));
        for (std::size_t i = 0; i < ref.rays.size(); ++i) {
            if (i % 2 == 0) {  // looking down: the tiny triangle, in front
                EXPECT_EQ(ref.hits[i].prim, 0u) << s << " ray " << i;
                EXPECT_GT(ref.hits[i].t, 0.f) << s << " ray " << i;
            } else {
                EXPECT_EQ(ref.hits[i].prim, i % 4 == 1 ? kNoHit : 1u) << s << " ray " << i;
                EXPECT_EQ(ref.occluded[i], i % 4 == 1 ? 0 : 1) << s << " ray " << i;
            }
        }
        for (const std::string& config : kConfigs)
            test::expect_matches(*make_accelerator(tris, parse_accel_config(config)), ref,
                                 config + " at a scale of " + std::to_string(s));
    }
}

// The packet kernels on the rays they are made for: a frame's primary rays in square tiles and the
// shadow rays of their hits, in batches of 8 x 8 and 16 x 16 (entry-point search) and of sizes that
// leave the last packet partly empty.
class CoherentPackets : public testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(CoherentPackets, SameHits) {
    const auto& [scene_name, config] = GetParam();
    const Scene* scene = test::structure_scene(scene_name);
    if (!scene) GTEST_SKIP() << "scene " << scene_name << " not found under " << test::scenes_dir();
    const int size = 64;
    std::vector<Ray> rays;
    const PinholeCamera camera(scene->camera, size, size);
    for (int tile : {8, 16})
        for (int ty = 0; ty < size; ty += tile)
            for (int tx = 0; tx < size; tx += tile)
                for (int y = ty; y < ty + tile; ++y)
                    for (int x = tx; x < tx + tile; ++x) rays.push_back(camera.primary(x, y));
    test::ReferenceAnswers ref = test::stored_reference(scene->triangles, rays);
    for (std::size_t i = 0; i < ref.rays.size(); ++i)
        if (ref.hits[i].is_hit()) {
            const SurfacePoint sp = surface_point(scene->triangles[ref.hits[i].prim], ref.rays[i], ref.hits[i]);
            rays.push_back(shadow_ray(sp, scene->light.position));
        }
    ref = test::stored_reference(scene->triangles, rays);
    const auto accel = make_accelerator(scene->triangles, parse_accel_config(config));
    for (std::size_t batch : {64u, 256u, 37u}) {
        std::vector<Hit> hits(rays.size());
        std::vector<std::uint8_t> occluded(rays.size());
        for (std::size_t i = 0; i < rays.size(); i += batch) {
            const std::size_t n = std::min(batch, rays.size() - i);
            accel->intersect(std::span(rays).subspan(i, n), std::span(hits).subspan(i, n));
            accel->occluded(std::span(rays).subspan(i, n), std::span(occluded).subspan(i, n));
        }
        std::size_t bad = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) bad += !(hits[i] == ref.hits[i]) || occluded[i] != ref.occluded[i];
        EXPECT_EQ(bad, 0u) << config << " on " << scene_name << ", batches of " << batch;
    }
}

std::vector<std::string> packet_configs() {
    std::vector<std::string> out;
    for (const std::string& c : kConfigs)
        if (c.find('+') != std::string::npos) out.push_back(c);
    return out;
}

INSTANTIATE_TEST_SUITE_P(Scenes, CoherentPackets,
                         testing::Combine(testing::ValuesIn(test::structure_scene_names()),
                                          testing::ValuesIn(packet_configs())),
                         [](const auto& info) {
                             return test::test_name(std::get<0>(info.param)) + "_" + name_of(std::get<1>(info.param));
                         });

// The SIMD brute force computes every reference answer of these tests (it is fast); here it is held
// to the scalar loop, the definition, on whole ray suites (a sanitized build: on a thirteenth of them,
// test::sanitized_sample).
TEST(BruteForcePackets, SameAnswersAsTheScalarLoop) {
    std::vector<std::pair<std::string, std::vector<Triangle>>> scenes = test::degenerate_scenes();
    scenes.push_back({"spheres", test::cached_scene("builtin:spheres?tris=2000").triangles});
    for (const auto& [name, tris] : scenes) {
        test::ReferenceAnswers ref;
        ref.rays = test::sanitized_sample(test::RaySuite(tris, test::small_suite()).rays());
        ref.hits.resize(ref.rays.size());
        ref.occluded.resize(ref.rays.size());
        const auto scalar = make_accelerator(tris, AccelConfig{"brute"});
        scalar->intersect(ref.rays, ref.hits);
        scalar->occluded(ref.rays, ref.occluded);
        for (detail::Isa isa : detail::available_isas()) {
            AccelConfig c{"brute"};
            c.simd = detail::to_string(isa);
            test::detail::expect_all_match(*make_accelerator(tris, c), ref, "brute+" + c.simd + " on " + name);
        }
    }
}

// A SIMD set that does not exist, or that this build or processor cannot run, is refused in the
// library's words (the program puts its --simd in front).
TEST(SimdSets, RefusedInTheLibrarysWords) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    auto error_of = [&](const std::string& simd) {
        try {
            make_accelerator(scene.triangles, AccelConfig{.kind = "kd", .simd = simd});
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(error_of("avx9"), "SIMD instruction set 'avx9' is not one of: auto, off, portable, sse, avx2, avx512");
    if (detail::available_isas().back() != detail::Isa::avx512) {
        const std::string unavailable = error_of("avx512");
        EXPECT_EQ(unavailable.rfind("SIMD instruction set avx512 is not available on this machine or in this build "
                                    "(available: auto, off, portable",
                                    0),
                  0u)
            << unavailable;
    }
}

// ---------------------------------------------------------------------------------------------
// Misuse and bad input through every path that traces rays (docs/RELIABILITY.md)

using test::error_of;

// A way of building an accelerator over triangles, by name.
struct Path {
    std::string name;
    std::function<std::unique_ptr<Accelerator>(std::span<const Triangle>)> make;
};

// Every path of this binary: the exact configurations above, brute force's loop and its SIMD sets,
// Embree's traversals where Embree is built in and this processor runs them natively, and the
// local-store model of each tree and traversal.
std::vector<Path> every_path() {
    std::vector<Path> out;
    auto direct = [&](const std::string& spec) {
        out.push_back({spec, [spec](std::span<const Triangle> tris) {
                           return make_accelerator(tris, parse_accel_config(spec));
                       }});
    };
    for (const std::string& c : kConfigs) direct(c);
    direct("brute");
    for (detail::Isa isa : detail::available_isas()) direct(std::string("brute+") + detail::to_string(isa));
    const std::vector<std::string> kinds = accelerator_kinds();
    if (std::find(kinds.begin(), kinds.end(), "embree") != kinds.end()) {
        const Triangle tri{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}};
        for (const std::string& t : accelerator_traversals("embree")) {
            try {
                make_accelerator(std::span(&tri, 1), AccelConfig{"embree", t});
            } catch (const Error&) {
                continue;  // a packet width this processor does not run natively
            }
            direct("embree:" + t);
        }
    }
    for (const std::string kind : {"kd", "bih"})
        for (const std::string& t : accelerator_traversals(kind))
            out.push_back({"local store " + kind + ":" + t, [kind, t](std::span<const Triangle> tris) {
                               return std::unique_ptr<Accelerator>(
                                   make_local_store_accelerator(tris, AccelConfig{kind, t}, LocalStoreConfig{}));
                           }});
    return out;
}
const std::vector<Path> kPaths = every_path();

std::vector<std::string> path_names() {
    std::vector<std::string> out;
    for (const Path& p : kPaths) out.push_back(p.name);
    return out;
}

class EveryPath : public testing::TestWithParam<std::string> {
protected:
    std::unique_ptr<Accelerator> make(std::span<const Triangle> tris) const {
        for (const Path& p : kPaths)
            if (p.name == GetParam()) return p.make(tris);
        throw std::logic_error("no path " + GetParam());
    }
};

// Spans of different lengths are refused before any ray is traced, in intersect and in occluded, with
// fewer results and with more; an empty batch is no error.
TEST_P(EveryPath, RefusesSpansOfDifferentLengths) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    const auto accel = make(scene.triangles);
    const std::vector<Ray> rays(5, Ray{scene.camera.position, 0.f, scene.bounds().center() - scene.camera.position});
    for (const std::size_t n : {4u, 6u, 0u}) {
        std::vector<Hit> hits(n, Hit{1.f, 7u, 0.f, 0.f});
        std::vector<std::uint8_t> occluded(n, 2);
        EXPECT_EQ(error_of([&] { accel->intersect(rays, hits); }),
                  "intersect: 5 rays but " + std::to_string(n) + " hits (the spans must have the same length)");
        EXPECT_EQ(error_of([&] { accel->occluded(rays, occluded); }),
                  "occluded: 5 rays but " + std::to_string(n) + " results (the spans must have the same length)");
        EXPECT_EQ(hits, std::vector<Hit>(n, Hit{1.f, 7u, 0.f, 0.f})) << "results written before the refusal";
        EXPECT_EQ(occluded, std::vector<std::uint8_t>(n, 2)) << "results written before the refusal";
    }
    EXPECT_EQ(error_of([&] { accel->intersect({}, {}); }), "no error");
    EXPECT_EQ(error_of([&] { accel->occluded({}, {}); }), "no error");
}

// A NaN or infinite coordinate anywhere is refused by the registry, naming the triangle, before a
// build can meet it.
TEST_P(EveryPath, RefusesNonFiniteVertices) {
    std::vector<Triangle> tris(4, Triangle{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}});
    for (const float bad : {std::nanf(""), kInfinity, -kInfinity})
        for (int corner = 0; corner < 3; ++corner) {
            std::vector<Triangle> t = tris;
            (corner == 0 ? t[2].v0 : corner == 1 ? t[2].v1 : t[2].v2)[corner] = bad;
            EXPECT_EQ(error_of([&] { make(t); }), "triangle 2 has a non-finite coordinate") << bad << " " << corner;
        }
}

// The rays of a batch that, were they valid, would hit the scene, mixed with valid ones, so that SIMD
// packets meet invalid lanes beside valid ones: NaN or infinite origins and directions, a zero
// direction, NaN bounds and tnear > tfar.
std::vector<Ray> invalid_rays(const Scene& scene) {
    const float nan = std::nanf("");
    const Ray aimed{scene.camera.position, 0.f, scene.bounds().center() - scene.camera.position, kInfinity};
    std::vector<std::function<void(Ray&)>> breaks;
    for (int axis = 0; axis < 3; ++axis)
        for (const float bad : {nan, kInfinity, -kInfinity}) {
            breaks.push_back([=](Ray& r) { r.org[axis] = bad; });
            breaks.push_back([=](Ray& r) { r.dir[axis] = bad; });
        }
    breaks.push_back([](Ray& r) { r.dir = Vec3{}; });
    breaks.push_back([](Ray& r) { r.dir = Vec3{-0.f, -0.f, -0.f}; });
    breaks.push_back([](Ray& r) { r.dir = Vec3{1e-40f, -1e-45f, 0.f}; });  // subnormal: no 1 / d
    breaks.push_back([=](Ray& r) { r.tnear = nan; });
    breaks.push_back([=](Ray& r) { r.tfar = nan; });
    breaks.push_back([](Ray& r) { r.tnear = 2.f, r.tfar = 1.f; });
    breaks.push_back([](Ray& r) { r.tnear = kInfinity; });  // [inf, inf]
    std::vector<Ray> out;
    for (const auto& b : breaks) {
        out.push_back(aimed);
        b(out.back());
    }
    return out;
}

// Invalid rays hit nothing (ray.hpp), on every path, and among valid rays in one batch they change
// nothing of the valid rays' answers (those of the valid rays traced alone: Embree's are its own).
TEST_P(EveryPath, InvalidRaysHitNothing) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    const auto accel = make(scene.triangles);
    const std::vector<Ray> invalid = invalid_rays(scene);
    std::vector<Ray> rays, valid_rays;
    std::vector<std::size_t> valid;  // where valid_rays[k] is in `rays`
    const PinholeCamera camera(scene.camera, 8, 8);
    for (std::size_t i = 0; i < invalid.size(); ++i) {
        rays.push_back(invalid[i]);
        for (std::size_t k = 0; k < i % 4; ++k) {  // 0 to 3 valid rays between invalid ones
            valid.push_back(rays.size());
            const int pixel = static_cast<int>(valid.size() % 64);
            valid_rays.push_back(camera.primary(pixel % 8, pixel / 8));
            rays.push_back(valid_rays.back());
        }
    }
    std::vector<Hit> alone(valid_rays.size());
    std::vector<std::uint8_t> alone_occluded(valid_rays.size());
    accel->intersect(valid_rays, alone);
    accel->occluded(valid_rays, alone_occluded);
    std::vector<Hit> want(rays.size());
    std::vector<std::uint8_t> want_occluded(rays.size(), 0);
    for (std::size_t k = 0; k < valid.size(); ++k) {
        want[valid[k]] = alone[k];
        want_occluded[valid[k]] = alone_occluded[k];
    }
    std::vector<Hit> hits(rays.size(), Hit{1.f, 7u, 0.f, 0.f});
    std::vector<std::uint8_t> occluded(rays.size(), 2);
    accel->intersect(rays, hits);
    accel->occluded(rays, occluded);
    for (std::size_t i = 0; i < rays.size(); ++i)
        EXPECT_TRUE(hits[i] == want[i] && occluded[i] == want_occluded[i])
            << "ray " << i << " " << test::describe(rays[i]) << ": prim " << hits[i].prim << " occluded "
            << int(occluded[i]) << ", want prim " << want[i].prim << " occluded " << int(want_occluded[i]);
    EXPECT_GT(std::count(want_occluded.begin(), want_occluded.end(), 1), 0) << "the valid rays should hit";
}

// An empty scene builds on every path and every ray misses it (valid or not); its report is made.
TEST_P(EveryPath, EmptySceneMissesEverything) {
    const std::vector<Triangle> none;
    const auto accel = make(none);
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    std::vector<Ray> rays = invalid_rays(scene);
    const PinholeCamera camera(scene.camera, 8, 8);
    for (int i = 0; i < 64; ++i) rays.push_back(camera.primary(i % 8, i / 8));
    std::vector<Hit> hits(rays.size(), Hit{1.f, 7u, 0.f, 0.f});
    std::vector<std::uint8_t> occluded(rays.size(), 2);
    accel->intersect(rays, hits);
    accel->occluded(rays, occluded);
    EXPECT_EQ(hits, std::vector<Hit>(rays.size(), Hit{}));
    EXPECT_EQ(occluded, std::vector<std::uint8_t>(rays.size(), 0));
    const AccelStats stats = accel->stats();
    EXPECT_EQ(stats.triangles, 0u);
    EXPECT_FALSE(stats.figures().empty());
}

// Many threads calling intersect and occluded on one accelerator at once, each over the whole ray set
// in batches, starting at different batches, get the answers of one thread, while one of them also
// asks for stats() (accelerator.hpp).
TEST_P(EveryPath, ConcurrentCallsGiveTheSingleThreadAnswers) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    const auto accel = make(scene.triangles);
    test::RaySuiteOptions options;
    options.random = options.inside = options.vertices = options.edges = 500;
    options.axis_parallel = options.planes = 200;
    const std::vector<Ray> rays = test::RaySuite(scene.triangles, options).rays();
    constexpr std::size_t kBatch = 64;
    const std::size_t batches = (rays.size() + kBatch - 1) / kBatch;
    struct Answers {
        std::vector<Hit> hits;
        std::vector<std::uint8_t> occluded;
        bool operator==(const Answers&) const = default;
    };
    auto trace = [&](Answers& a, std::size_t first_batch) {
        a.hits.assign(rays.size(), Hit{});
        a.occluded.assign(rays.size(), 0);
        for (std::size_t k = 0; k < batches; ++k) {
            const std::size_t i = (first_batch + k) % batches * kBatch, n = std::min(kBatch, rays.size() - i);
            accel->intersect(std::span(rays).subspan(i, n), std::span(a.hits).subspan(i, n));
            accel->occluded(std::span(rays).subspan(i, n), std::span(a.occluded).subspan(i, n));
        }
    };
    Answers alone;
    trace(alone, 0);
    constexpr unsigned kThreads = 8;
    std::vector<Answers> together(kThreads);
    std::barrier start(kThreads);
    std::vector<std::thread> threads;
    for (unsigned t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            start.arrive_and_wait();
            for (int round = 0; round < 3; ++round) {
                trace(together[t], t * batches / kThreads + round);
                if (t == 0) accel->stats();  // a report made while the others trace
            }
        });
    for (std::thread& t : threads) t.join();
    for (unsigned t = 0; t < kThreads; ++t) EXPECT_TRUE(together[t] == alone) << "thread " << t;
}

INSTANTIATE_TEST_SUITE_P(Structures, EveryPath, testing::ValuesIn(path_names()),
                         [](const auto& info) { return name_of(info.param); });

// make_brute_force, public beside the registry, refuses non-finite vertices as make_accelerator does.
TEST(BruteForceReference, RefusesNonFiniteVertices) {
    const std::vector<Triangle> tris{{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, std::nanf(""), 0.f}}};
    EXPECT_EQ(error_of([&] { make_brute_force(tris, AccelConfig{"brute"}); }),
              "triangle 0 has a non-finite coordinate");
}

}  // namespace
}  // namespace cellrt
