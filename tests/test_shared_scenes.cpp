// The shared real scenes (../shared/scenes, or CELLRT_SCENES): each loads with the triangle count of
// that folder's README, and Sponza loads well under a second. Skipped, with a message, when absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "cellrt/scene.hpp"
#include "core/timer.hpp"
#include "sanitizers.hpp"
#include "scenes.hpp"

namespace cellrt {
namespace {

// The README's table, as it stands: scene name and triangle count.
const std::map<std::string, std::size_t> kTriangles{
    {"sponza", 66454}, {"sibenik", 75284}, {"bunny", 69451}, {"teapot", 6320}};

class SharedScene : public ::testing::TestWithParam<std::string> {};

TEST_P(SharedScene, HasTheReadmeTriangleCount) {
    CELLRT_REQUIRE_SHARED_SCENE(path, GetParam());
    const Scene scene = load_scene(path);
    EXPECT_EQ(scene.triangles.size(), kTriangles.at(GetParam()));
    EXPECT_EQ(scene.name, GetParam());
    EXPECT_GT(scene.width, 0);
    EXPECT_GT(scene.height, 0);
}

INSTANTIATE_TEST_SUITE_P(All, SharedScene, ::testing::Values("sponza", "sibenik", "bunny", "teapot"),
                         [](const auto& info) { return info.param; });

// The table above is the README's: rows "| name | 66,454 | ...".
TEST(SharedScenes, ReadmeTableMatchesTheExpectedCounts) {
    const auto readme = std::filesystem::path(test::scenes_dir()) / "README.md";
    if (!std::filesystem::exists(readme)) GTEST_SKIP() << readme << " not found (set CELLRT_SCENES)";
    std::ifstream in(readme);
    std::map<std::string, std::size_t> table;
    for (std::string line; std::getline(in, line);) {
        std::istringstream row(line);
        std::string bar, name, count;
        if (!(row >> bar >> name >> bar >> count) || bar != "|" || !kTriangles.contains(name)) continue;
        std::erase(count, ',');
        table[name] = std::stoul(count);
    }
    EXPECT_EQ(table, kTriangles);
}

// A sanity bound, not a benchmark: the strict OBJ reader must not make loading slow. Only a
// Release build is held to it.
TEST(SharedScenes, SponzaLoadsWellUnderASecond) {
    CELLRT_REQUIRE_SHARED_SCENE(path, "sponza");
    CELLRT_SKIP_UNDER_SANITIZERS("a time bound for uninstrumented code");
    const Timer timer;
    const Scene scene = load_scene(path);
    const double seconds = timer.seconds();
    std::printf("sponza: %zu triangles loaded in %.3f s\n", scene.triangles.size(), seconds);
#ifdef NDEBUG
    EXPECT_LT(seconds, 1.0);
#endif
}

}  // namespace
}  // namespace cellrt
