// What the benchmark programs share: which scenes they read and how they summarise repeated timings.
#pragma once

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cellrt/accel.hpp"

namespace cellrt::bench {

// The median of repeated timings: robust to the odd slow run on a shared machine.
inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// The scene a benchmark argument names: a builtin:... spec as it is, a shared scene's name as
// DIR/NAME/NAME.json. A shared scene that is not there is skipped with a message (nullopt).
inline std::optional<std::string> scene_spec(const std::string& scenes_dir, const std::string& name) {
    if (name.rfind("builtin:", 0) == 0) return name;
    const std::string spec = (std::filesystem::path(scenes_dir) / name / (name + ".json")).string();
    if (std::filesystem::exists(spec)) return spec;
    std::fprintf(stderr, "skipping %s: %s not found\n", name.c_str(), spec.c_str());
    return std::nullopt;
}

// Whether this binary has the structure `kind` (Embree is optional); a missing one is skipped with a
// message.
inline bool built_in(const std::string& kind) {
    const auto kinds = accelerator_kinds();
    if (std::find(kinds.begin(), kinds.end(), kind) != kinds.end()) return true;
    std::fprintf(stderr, "skipping %s: not built into this binary\n", kind.c_str());
    return false;
}

}  // namespace cellrt::bench
