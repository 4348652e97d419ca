// The sanitizers this test program was built with (CMake's CELLRT_SANITIZE; empty for none), and the
// skip, with its reason, of a test that cannot hold under them: valgrind cannot run a program built
// with AddressSanitizer or ThreadSanitizer (both map shadow memory valgrind will not give them), and a
// time bound means nothing for code several times slower. CTest lists every skipped test at the end.
#pragma once

#include <gtest/gtest.h>

#include <string_view>

namespace cellrt::test {

inline constexpr std::string_view kSanitizers = CELLRT_SANITIZE;

}  // namespace cellrt::test

#define CELLRT_SKIP_UNDER_SANITIZERS(why)                                                                  \
    if (!::cellrt::test::kSanitizers.empty())                                                              \
    GTEST_SKIP() << "built with -fsanitize=" << ::cellrt::test::kSanitizers << ": " << why
