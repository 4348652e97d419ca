// Built-in procedural scenes, so that cellrt needs no files. Each is deterministic in its name,
// seed and size: the same spec gives the same triangles on every machine and thread count.
//
// Spec: `builtin:NAME[?key=value[&key=value...]]`, keys: `tris` (approximate triangle count),
// `seed` (unsigned integer). Unknown names, keys or bad values are errors naming them.
#pragma once

#include <string>
#include <vector>

#include "cellrt/scene.hpp"

namespace cellrt {

struct BuiltinInfo {
    std::string name;
    std::string description;
    std::size_t default_tris;
};

std::vector<BuiltinInfo> builtin_scenes();

// The scene `cellrt render` shows when given none.
std::string default_scene_spec();

Scene make_builtin_scene(const std::string& spec);

// Throws as make_builtin_scene does for a bad spec, without making the triangles: a program can refuse
// a mistyped scene before any work.
void check_builtin_spec(const std::string& spec);

}  // namespace cellrt
