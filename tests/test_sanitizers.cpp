// What the sanitized runs change in the suite itself (docs/RELIABILITY.md).
#include <gtest/gtest.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <memory>
#include <string_view>

#include "sanitizers.hpp"

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

}  // namespace
}  // namespace cellrt
