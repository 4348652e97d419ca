// File loaders. Each throws cellrt::Error whose message starts with "FILE:LINE:" (or "FILE:" for
// whole-file problems, "FILE: field X" for view files) and says what was expected; nothing else
// escapes them (a number beyond its type's range, a path the system cannot look up) but
// std::bad_alloc.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cellrt/scene.hpp"

namespace cellrt {

// Wavefront OBJ: `v x y z [w]`, `f` with a, a/b, a//c, a/b/c and negative (relative) indices;
// polygons are triangulated as fans (`fo` read as `f`); statements that would change the geometry
// unread (`call`, `csh`, free-form curves and surfaces), a `\` continuation and a CR before a line's
// end are refused; every other statement (vt, vn, g, o, s, usemtl, ...) is skipped.
std::vector<Triangle> load_obj(const std::string& path);

// Stanford PLY, ASCII, binary_little_endian or binary_big_endian: x, y, z of element `vertex` (any
// scalar type) and the index list `vertex_indices` (or `vertex_index`) of element `face`, polygons
// triangulated as fans; every other property and element is read, checked and skipped. Errors in an
// ASCII file give "FILE:LINE:", in binary data "FILE: ELEMENT INDEX:" (records counted from 0).
std::vector<Triangle> load_ply(const std::string& path);

// A glTF 2.0 scene: its triangles and the view of its first perspective camera, if any.
struct GltfScene {
    std::vector<Triangle> triangles;
    std::optional<Camera> camera;
    std::optional<float> aspect_ratio;  // the camera's width / height, where it gives one
};

// The most triangles load_gltf makes by default once the nodes' instances are flattened: a mesh
// referenced by many nodes would otherwise let a small file ask for any amount of memory.
inline constexpr std::size_t kMaxGltfTriangles = std::size_t{1} << 28;

// glTF 2.0 (docs/FORMATS.md): a .gltf file (JSON; buffers in files beside it or embedded as base64
// data URIs) or a .glb file (binary container), read through tinygltf. The default scene (or the
// first) is flattened: every node's meshes in world space under the product of its ancestors'
// transforms (matrix or translation-rotation-scale). Only triangle primitives (mode 4) are accepted;
// any other mode is refused. Accessors are checked for type (POSITION: VEC3 of float; indices:
// SCALAR of unsigned byte, short or int), counts, byte ranges inside their buffer view and buffer, and
// indices below the vertex count. Errors say "FILE: mesh M ('NAME') primitive P: ..." or name the node,
// accessor, buffer view or camera at fault; more than `max_triangles` triangles are refused before
// any is made.
GltfScene load_gltf(const std::string& path, std::size_t max_triangles = kMaxGltfTriangles);

// A mesh file chosen by extension (.obj, .ply, .gltf or .glb), case-insensitive.
std::vector<Triangle> load_mesh(const std::string& path);

// View file (JSON, format of shared/scenes/README.md): the mesh path relative to the file, camera,
// point light and image size.
Scene load_view_file(const std::string& path);

// The files loading the scene `spec` (load_scene's argument) reads, as (what, path), so that a
// program can refuse an output that would replace one of them before any work: ("scene", spec); for
// a view file, ("mesh", the mesh it names); for a .gltf file, itself or a view file's mesh, ("glTF
// buffer", each external buffer it names, its URI as a path beside the .gltf file); none for a
// built-in scene. A file that cannot be read as JSON gives no more (loading it names what is wrong).
std::vector<std::pair<std::string, std::string>> scene_files(const std::string& spec);

// The files of every scene in `specs`, in order (a sweep's inputs).
std::vector<std::pair<std::string, std::string>> scene_files(const std::vector<std::string>& specs);

}  // namespace cellrt
