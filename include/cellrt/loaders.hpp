// File loaders. Each throws cellrt::Error whose message starts with "FILE:LINE:" (or "FILE:" for
// whole-file problems, "FILE: field X" for view files) and says what was expected; nothing else
// escapes them (a number beyond its type's range, a path the system cannot look up) but
// std::bad_alloc.
#pragma once

#include <string>
#include <vector>

#include "cellrt/scene.hpp"

namespace cellrt {

// Wavefront OBJ: `v x y z [w]`, `f` with a, a/b, a//c, a/b/c and negative (relative) indices;
// polygons are triangulated as fans; every other statement (vt, vn, g, o, s, usemtl, ...) is skipped.
std::vector<Triangle> load_obj(const std::string& path);

// Stanford PLY, ASCII, binary_little_endian or binary_big_endian: x, y, z of element `vertex` (any
// scalar type) and the index list `vertex_indices` (or `vertex_index`) of element `face`, polygons
// triangulated as fans; every other property and element is read, checked and skipped. Errors in an
// ASCII file give "FILE:LINE:", in binary data "FILE: ELEMENT INDEX:" (records counted from 0).
std::vector<Triangle> load_ply(const std::string& path);

// A mesh file chosen by extension (.obj or .ply), case-insensitive.
std::vector<Triangle> load_mesh(const std::string& path);

// View file (JSON, format of shared/scenes/README.md): the mesh path relative to the file, camera,
// point light and image size.
Scene load_view_file(const std::string& path);

}  // namespace cellrt
