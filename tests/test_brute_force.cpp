// Brute force against itself through the ray suite: checks the harness (invalid rays, limited
// intervals) on a scene whose answers are known to be consistent.
#include <gtest/gtest.h>

#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "ray_suite.hpp"
#include "scenes.hpp"

namespace cellrt {
namespace {

TEST(BruteForce, SuiteCoversHitsMissesAndInvalidRays) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    const test::ReferenceAnswers& ref = test::cached_reference("builtin:spheres?tris=600", scene.triangles);
    std::size_t hits = 0, occluded = 0;
    for (std::size_t i = 0; i < ref.rays.size(); ++i) {
        hits += ref.hits[i].is_hit();
        occluded += ref.occluded[i];
        EXPECT_EQ(ref.hits[i].is_hit(), ref.occluded[i] != 0) << "ray " << i;
    }
    EXPECT_GT(ref.rays.size(), 100000u);
    EXPECT_GT(hits, ref.rays.size() / 5);
    EXPECT_LT(hits, ref.rays.size());
    const auto brute = make_brute_force(scene.triangles, AccelConfig{"brute"});
    EXPECT_EQ(test::expect_matches(*brute, ref, "brute force"), 0u);
}

// The cache's key holds the suite's base rays only; a file whose limited copies differ from what
// RaySuite::limited makes of its hits (written by an older version of the test code) must be
// recomputed, not trusted: a sample of every 97th answer would pass it, the answers being right for
// the rays the file holds.
TEST(BruteForce, StoredSuiteRecomputesStaleLimitedRays) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    test::RaySuiteOptions few;
    few.random = few.inside = few.vertices = few.edges = 300;
    few.axis_parallel = 120;
    few.planes = 200;
    const test::ReferenceAnswers fresh = test::reference_suite(scene.triangles, few);
    const std::vector<Ray> base = test::RaySuite(scene.triangles, few).rays();
    // A cache folder of this test's own, and the caller's restored however the test ends.
    struct CacheFolder {
        std::string dir = ::testing::TempDir() + "cellrt_stale_cache_" + std::to_string(::getpid());
        const char* previous = std::getenv("CELLRT_TEST_CACHE");
        std::string saved = previous ? previous : "";
        CacheFolder() { ::setenv("CELLRT_TEST_CACHE", dir.c_str(), 1); }
        ~CacheFolder() {
            std::filesystem::remove_all(dir);
            if (previous) ::setenv("CELLRT_TEST_CACHE", saved.c_str(), 1);
            else ::unsetenv("CELLRT_TEST_CACHE");
        }
    } folder;
    const test::ReferenceAnswers first = test::stored_suite(scene.triangles, few);
    ASSERT_EQ(first.rays.size(), fresh.rays.size());
    ASSERT_GT(first.rays.size(), base.size());  // the last ray is a limited copy

    test::ReferenceAnswers stale = first;
    const std::size_t last = stale.rays.size() - 1;
    ASSERT_NE(last % 97, 0u);  // not in the sample that is recomputed
    stale.rays[last].tfar = std::nextafter(stale.rays[last].tfar, 0.f);
    ASSERT_NE(stale.rays[last].tfar, first.rays[last].tfar);
    test::detail::write_reference(test::stored_answers_path(scene.triangles, base), stale);

    const test::ReferenceAnswers again = test::stored_suite(scene.triangles, few);
    ASSERT_EQ(again.rays.size(), fresh.rays.size());
    EXPECT_EQ(std::memcmp(again.rays.data(), fresh.rays.data(), fresh.rays.size() * sizeof(Ray)), 0);
}

TEST(BruteForce, RejectsUnknownParameterAndTraversal) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    AccelConfig c{"brute"};
    c.params["leaf"] = "4";
    EXPECT_THROW(make_accelerator(scene.triangles, c), Error);
    AccelConfig t{"brute", "branchless"};
    EXPECT_THROW(make_accelerator(scene.triangles, t), Error);
    EXPECT_THROW(make_accelerator(scene.triangles, AccelConfig{"octree"}), Error);
}

}  // namespace
}  // namespace cellrt
