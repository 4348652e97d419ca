// Access to the shared scenes for tests: their folder, and a skip with a message when absent.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "cellrt/scene.hpp"

namespace cellrt::test {

inline std::string scenes_dir() {
    if (const char* env = std::getenv("CELLRT_SCENES")) return env;
    return CELLRT_SCENES_DIR;
}

// Path of a shared scene's view file, e.g. shared_view("teapot"); empty when absent.
inline std::string shared_view(const std::string& name) {
    const auto p = std::filesystem::path(scenes_dir()) / name / (name + ".json");
    return std::filesystem::exists(p) ? p.string() : std::string();
}

// Loads a scene once per test program (by spec: view file path or builtin:...).
inline const Scene& cached_scene(const std::string& spec) {
    static std::mutex mutex;
    static std::map<std::string, std::unique_ptr<Scene>> cache;
    std::lock_guard lock(mutex);
    auto& slot = cache[spec];
    if (!slot) slot = std::make_unique<Scene>(load_scene(spec));
    return *slot;
}

#define CELLRT_REQUIRE_SHARED_SCENE(path_var, name)                                                      \
    const std::string path_var = ::cellrt::test::shared_view(name);                                     \
    if (path_var.empty()) GTEST_SKIP() << "shared scene '" << name << "' not found under "               \
                                       << ::cellrt::test::scenes_dir() << " (set CELLRT_SCENES)"

}  // namespace cellrt::test
