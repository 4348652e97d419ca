// Every acceleration structure and traversal returns exactly the brute-force hits (closest hit: t,
// triangle and barycentrics; any hit) on the ray suite of ray_suite.hpp, on built-in scenes, the
// shared real scenes and a catalogue of degenerate inputs.
#include <gtest/gtest.h>

#include "cellrt/accel.hpp"
#include "ray_suite.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

// KIND:TRAVERSAL of every exact structure path.
const std::vector<std::string> kConfigs = {"kd:rec", "kd:branched", "kd:branchless", "bih:branched", "bih:branchless"};

AccelConfig parse(const std::string& text) {
    const auto colon = text.find(':');
    return AccelConfig{text.substr(0, colon), text.substr(colon + 1)};
}

std::string name_of(const std::string& config) {
    std::string s = config;
    std::replace(s.begin(), s.end(), ':', '_');
    return s;
}

class AgainstBruteForce : public testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(AgainstBruteForce, SameHits) {
    const auto& [scene_name, config] = GetParam();
    const Scene* scene = test::structure_scene(scene_name);
    if (!scene) GTEST_SKIP() << "scene " << scene_name << " not found under " << test::scenes_dir();
    const test::ReferenceAnswers& ref = test::cached_reference(scene_name, scene->triangles);
    const auto accel = make_accelerator(scene->triangles, parse(config));
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
        const test::ReferenceAnswers ref = test::reference_suite(tris, test::small_suite());
        test::expect_matches(*make_accelerator(tris, parse(GetParam())), ref, GetParam() + " on " + name);
    }
}

INSTANTIATE_TEST_SUITE_P(Structures, DegenerateInputs, testing::ValuesIn(kConfigs),
                         [](const auto& info) { return name_of(info.param); });

}  // namespace
}  // namespace cellrt
