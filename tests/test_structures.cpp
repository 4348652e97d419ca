// Every acceleration structure and traversal returns exactly the brute-force hits (closest hit: t,
// triangle and barycentrics; any hit) on the ray suite of ray_suite.hpp, on built-in scenes, the
// shared real scenes and a catalogue of degenerate inputs.
#include <gtest/gtest.h>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "ray_suite.hpp"
#include "simd/isa.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

// Every exact structure path: KIND:TRAVERSAL for single rays, KIND+SIMD for the packet kernels of
// each instruction set this machine runs (for the wide BVH, its single-ray kernels of that set); and
// the BIH built with the SAH, by both.
std::vector<std::string> exact_configs() {
    std::vector<std::string> out = {"kd:rec", "kd:branched", "kd:branchless", "bih:branched", "bih:branchless",
                                    "bih:branched@split=sah", "bih+auto@split=sah"};
    for (detail::Isa isa : detail::available_isas())
        for (const char* kind : {"kd", "bih", "bvh"}) out.push_back(std::string(kind) + "+" + detail::to_string(isa));
    return out;
}
const std::vector<std::string> kConfigs = exact_configs();

std::string name_of(const std::string& config) {
    std::string s = config;
    std::replace(s.begin(), s.end(), ':', '_');
    for (const char c : {'+', '@', '='}) std::replace(s.begin(), s.end(), c, '_');
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
            rays.push_back(shadow_ray(sp.position, sp.normal, scene->light.position));
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
// to the scalar loop, the definition, on whole ray suites.
TEST(BruteForcePackets, SameAnswersAsTheScalarLoop) {
    std::vector<std::pair<std::string, std::vector<Triangle>>> scenes = test::degenerate_scenes();
    scenes.push_back({"spheres", test::cached_scene("builtin:spheres?tris=2000").triangles});
    for (const auto& [name, tris] : scenes) {
        test::ReferenceAnswers ref;
        ref.rays = test::RaySuite(tris, test::small_suite()).rays();
        ref.hits.resize(ref.rays.size());
        ref.occluded.resize(ref.rays.size());
        const auto scalar = make_accelerator(tris, AccelConfig{"brute"});
        scalar->intersect(ref.rays, ref.hits);
        scalar->occluded(ref.rays, ref.occluded);
        for (detail::Isa isa : detail::available_isas()) {
            AccelConfig c{"brute"};
            c.simd = detail::to_string(isa);
            test::expect_matches(*make_accelerator(tris, c), ref, "brute+" + c.simd + " on " + name);
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

}  // namespace
}  // namespace cellrt
