// What the sanitized runs change in the suite itself (docs/RELIABILITY.md).
#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <string_view>
#include <tuple>

#include "ray_suite.hpp"
#include "sanitizers.hpp"
#include "scenes.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

constexpr bool kThreadSanitizer = test::kSanitizers.find("thread") != std::string_view::npos;

// Under ThreadSanitizer TBB runs every task on the thread that waits for it. Debian's libtbb is not
// instrumented, so TSan cannot see how TBB orders a task after its spawn and before its wait: it
// reports each access of a task to the spawner's data as a race, and its search among the addresses
// already reported makes a parallel build of a few thousand triangles take many minutes.
std::unique_ptr<tbb::global_control> limit_tbb() {
    if (!kThreadSanitizer) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
}
const std::unique_ptr<tbb::global_control> kTbbLimit = limit_tbb();

TEST(Sanitizers, TbbRunsOnOneThreadOnlyUnderThreadSanitizer) {
    const std::size_t allowed = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    if (kThreadSanitizer) {
        EXPECT_EQ(allowed, 1u);
    } else {
        EXPECT_EQ(allowed, static_cast<std::size_t>(tbb::info::default_concurrency()));
    }
}

// The sanitized runs trace a thirteenth of each ray suite (test::sanitized_sample): every thirteenth ray and
// every invalid one, so that each kind of ray the suite makes is still among them.
TEST(Sanitizers, SuiteSampleKeepsEveryKindOfRay) {
    constexpr std::size_t stride = test::kSanitizedSampleStride;
    EXPECT_EQ(test::kSanitizedStride, test::kSanitizers.empty() ? 1u : stride);
    const std::vector<Ray> rays = test::RaySuite(test::cached_scene("builtin:spheres?tris=600").triangles,
                                                 test::small_suite()).rays();
    const std::vector<Ray> sample = test::sanitized_sample(rays, stride);
    const auto invalid = [](const std::vector<Ray>& rs) { return std::ranges::count_if(rs, test::is_invalid); };
    EXPECT_EQ(invalid(rays), 10);
    EXPECT_EQ(invalid(sample), 10);
    EXPECT_GE(sample.size(), rays.size() / stride);
    EXPECT_LE(sample.size(), rays.size() / stride + 1 + 10);
    // The axis-parallel directions: axis, sign, and the signs of the two zero components.
    using Kind = std::tuple<int, bool, bool, bool>;
    const auto axis_kinds = [](const std::vector<Ray>& rs) {
        std::set<Kind> kinds;
        for (const Ray& r : rs)
            for (int a = 0; a < 3; ++a)
                if (r.dir[(a + 1) % 3] == 0.f && r.dir[(a + 2) % 3] == 0.f && r.dir[a] != 0.f && std::isfinite(r.dir[a]))
                    kinds.insert({a, std::signbit(r.dir[a]), std::signbit(r.dir[(a + 1) % 3]),
                                  std::signbit(r.dir[(a + 2) % 3])});
        return kinds;
    };
    EXPECT_EQ(axis_kinds(rays).size(), 12u);
    EXPECT_EQ(axis_kinds(sample), axis_kinds(rays));
    EXPECT_GT(std::ranges::count_if(sample, [](const Ray& r) { return r.tnear > 0.f && !test::is_invalid(r); }), 0);
}

}  // namespace
}  // namespace cellrt
