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
