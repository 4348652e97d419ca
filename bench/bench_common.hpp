// What the benchmark programs share: which scenes they read and how they summarise repeated timings.
#pragma once

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <CLI/CLI.hpp>

#include "cellrt/accel.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "kernel/named.hpp"
#include "simd/isa.hpp"

namespace cellrt::bench {

// The check of a results file's option: an empty name is refused as the programs' other paths are
// ("--json: must not be empty"), where it used to run the sweep and write nothing.
inline CLI::Validator non_empty_path() {
    return CLI::Validator([](const std::string& s) { return s.empty() ? std::string("must not be empty") : std::string(); },
                          "PATH");
}

// The median of repeated timings: robust to the odd slow run on a shared machine.
inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// The process's peak resident memory (VmHWM) in bytes since the last reset_peak_memory(), or 0 where
// /proc does not tell (not Linux).
inline double peak_memory_bytes() {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) * 1024.0;  // in kB
    return 0.0;
}
// Starts a new peak: freed heap memory goes back to the system first (glibc), then Linux's clear_refs
// "5" sets VmHWM to the current resident size.
inline void reset_peak_memory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
    std::ofstream("/proc/self/clear_refs") << "5";
}
inline double resident_memory_bytes() {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) * 1024.0;
    return 0.0;
}

// The scene a benchmark argument names: a builtin:... spec as it is, a shared scene's name as
// DIR/NAME/NAME.json.
inline std::string scene_file(const std::string& scenes_dir, const std::string& name) {
    if (name.rfind("builtin:", 0) == 0) return name;
    return (std::filesystem::path(scenes_dir) / name / (name + ".json")).string();
}

// Whether the scene `spec` (of scene_file) is there: a builtin one always is, once its spec is read
// (a bad one throws, naming it: found by audit, 2026-12-07, after the scenes before it were measured).
inline bool scene_found(const std::string& spec) {
    if (spec.rfind("builtin:", 0) != 0) return std::filesystem::exists(spec);
    check_builtin_spec(spec);
    return true;
}

inline void print_skipped_scene(const std::string& name, const std::string& spec) {
    std::fprintf(stderr, "skipping %s: %s not found\n", name.c_str(), spec.c_str());
}

// scene_file's spec where the scene is there; a shared scene that is not is skipped with a message
// (nullopt).
inline std::optional<std::string> scene_spec(const std::string& scenes_dir, const std::string& name) {
    std::string spec = scene_file(scenes_dir, name);
    if (scene_found(spec)) return spec;
    print_skipped_scene(name, spec);
    return std::nullopt;
}

// Whether this processor runs the SIMD set `c` names (Embree ignores it): a configuration naming one
// it lacks (+avx512 on a machine without it) is skipped with a message, not refused.
inline bool simd_runs_here(const AccelConfig& c) {
    if (c.kind == "embree" || c.simd.empty() || c.simd == "off") return true;
    // A name that is no set at all (`+avx3`) is the build's error to report, not a set to skip.
    static const std::vector<std::string> kSets = {"auto", "portable", "sse", "avx2", "avx512"};
    if (std::find(kSets.begin(), kSets.end(), c.simd) == kSets.end()) return true;
    try {
        detail::parse_isa(c.simd);
        return true;
    } catch (const Error&) {
        return false;
    }
}

// Refuses, before any run, a --configs entry this binary cannot read: a malformed string, a kind
// cellrt does not have (Embree, which a build may lack, is skipped later instead: built_in), a
// traversal its kind does not have, a tree's kernel named with SIMD packets (names_replaced_traversal),
// and anything else its build refuses (a parameter's name or value), found by building it over one
// triangle: such a configuration was skipped at the first scene's build with a message and status 0
// (found by audit, 2026-12-07).
inline void check_configs(const std::vector<std::string>& configs) {
    const auto kinds = accelerator_kinds();
    for (const std::string& text : configs) {
        try {
            const AccelConfig c = parse_accel_config(text);
            if (c.kind == "embree" && std::find(kinds.begin(), kinds.end(), c.kind) == kinds.end()) continue;
            const auto& traversals = accelerator_traversals(c.kind);  // refuses an unknown kind, naming the kinds
            if (!c.traversal.empty() && std::find(traversals.begin(), traversals.end(), c.traversal) == traversals.end())
                throw Error("unknown traversal '" + c.traversal + "' of " + c.kind + " (choose one of: " +
                            detail::join_names(traversals) + ")");
            if (names_replaced_traversal(c))
                throw Error("names a single-ray kernel ('" + c.traversal + "') and SIMD packets ('" + c.simd +
                            "'), which would replace it: leave one of them out");
            static const Triangle kOne{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}};
            if (simd_runs_here(c)) make_accelerator(std::span<const Triangle>(&kOne, 1), c);
        } catch (const Error& e) {
            throw Error("--configs '" + text + "': " + e.what());
        }
    }
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
