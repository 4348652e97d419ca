// The public API's one header and its version.
#include <gtest/gtest.h>

#include <string>

#include "cellrt/cellrt.hpp"

namespace cellrt {
namespace {

TEST(PublicApi, VersionIsTheProjectsVersion) {
    EXPECT_EQ(std::string(CELLRT_VERSION_STRING), CELLRT_PROJECT_VERSION);
    EXPECT_EQ(std::to_string(CELLRT_VERSION_MAJOR) + "." + std::to_string(CELLRT_VERSION_MINOR) + "." +
                  std::to_string(CELLRT_VERSION_PATCH),
              CELLRT_PROJECT_VERSION);
    EXPECT_EQ(CELLRT_VERSION, CELLRT_VERSION_MAJOR * 10000 + CELLRT_VERSION_MINOR * 100 + CELLRT_VERSION_PATCH);
}

// The umbrella header alone is enough to load a scene, build a structure and trace.
TEST(PublicApi, TheUmbrellaHeaderServesAWholeQuery) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=500");
    const auto accel = make_accelerator(scene.triangles, parse_accel_config("bih"));
    Ray ray;
    ray.org = scene.camera.position;
    ray.dir = scene.camera.look_at - scene.camera.position;
    Hit hit, reference;
    accel->intersect(std::span(&ray, 1), std::span(&hit, 1));
    make_accelerator(scene.triangles, parse_accel_config("brute"))->intersect(std::span(&ray, 1), std::span(&reference, 1));
    ASSERT_TRUE(reference.is_hit());
    EXPECT_EQ(hit.prim, reference.prim);
    EXPECT_EQ(hit.t, reference.t);
}

}  // namespace
}  // namespace cellrt
