#include "cellrt/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "cellrt/builtin.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "core/files.hpp"
#include "cellrt/image.hpp"
#include "cellrt/loaders.hpp"
#include "core/read_file.hpp"

namespace cellrt {

Box3 Scene::bounds() const {
    Box3 b;
    for (const Triangle& t : triangles) b.extend(t.bounds());
    return b;
}

void set_default_view(Scene& scene) {
    // A scene without triangles is viewed as the unit cube around the origin: its empty bounds gave a
    // camera of NaNs (found by audit, 2026-12-07).
    const Box3 b = scene.triangles.empty() ? Box3{Vec3{-0.5f}, Vec3{0.5f}} : scene.bounds();
    const Vec3 c = b.center();
    const float radius = std::max(0.5f * length(b.extent()), 1e-6f);
    const Vec3 dir = normalize(Vec3{1.f, 0.6f, 1.4f});
    scene.camera.fov_y_deg = 45.f;
    // Distance at which a sphere of `radius` fits in a 45-degree field of view, with a margin.
    scene.camera.position = c + dir * (radius * 2.8f);
    scene.camera.look_at = c;
    scene.camera.up = {0.f, 1.f, 0.f};
    scene.light.position = c + Vec3{-0.6f, 1.5f, 0.9f} * (radius * 2.f);
    scene.light.color = {1.f, 1.f, 1.f};
}

// Finite triangles can still defeat the default view in float arithmetic: a mesh so large that a
// length overflows (the extent's, or the camera's distance to the centre, whose square passes
// float's range from about 1.8e19: coordinates of about 4e18 around the origin), or one so small for
// its distance from the origin that the camera rounds onto the centre. Said where the cause is
// known, rather than later as a camera or light at fault. Non-finite triangles are left to
// validate_scene, which names the first of them.
std::string default_view_problem(const Scene& scene, bool camera_too) {
    const Box3 b = scene.bounds();
    if (!is_finite(b.lo) || !is_finite(b.hi)) return {};
    bool framed = is_finite(scene.light.position);
    if (camera_too) try {
            PinholeCamera(scene.camera, 1, 1);
        } catch (const Error&) {
            framed = false;
        }
    if (framed) return {};
    char span[160];
    std::snprintf(span, sizeof span, "(%.9g, %.9g, %.9g) to (%.9g, %.9g, %.9g)", b.lo.x, b.lo.y, b.lo.z, b.hi.x,
                  b.hi.y, b.hi.z);
    // With a camera of its own (a glTF file's), only the default light was placed.
    return std::string("the mesh spans ") + span +
           (camera_too ? ", which the default view cannot frame in float arithmetic"
                       : ", for which the default light cannot be placed in float arithmetic");
}

std::string light_color_problem(const Vec3& color) {
    // A colour past float's range (1e39 in a view file) would shade pixels infinite.
    if (!is_finite(color)) return "the light color is not finite";
    // Light is added, never taken away: a negative channel shaded pixels below zero.
    if (color.x < 0.f || color.y < 0.f || color.z < 0.f) return "the light color has a negative channel";
    if (color.x > kMaxLightChannel || color.y > kMaxLightChannel || color.z > kMaxLightChannel)
        return "the light color has a channel above 1e+30, which the shading's sums could carry past float's range";
    return "";
}

void validate_scene(const Scene& scene, const std::string& where) {
    if (scene.triangles.empty()) throw Error(where + ": the mesh has no triangles");
    try {
        check_finite(scene.triangles);
        if (!is_finite(scene.light.position)) throw Error("the light position is not finite");
        if (const std::string why = light_color_problem(scene.light.color); !why.empty()) throw Error(why);
        PinholeCamera(scene.camera, scene.width, scene.height);
    } catch (const Error& e) {
        throw Error(where + ": " + e.what());
    }
}

std::vector<Triangle> load_mesh(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".obj") return load_obj(path);
    if (ext == ".ply") return load_ply(path);
    if (ext == ".gltf" || ext == ".glb") return load_gltf(path).triangles;
    throw Error(path + ": unknown mesh format '" + ext + "' (expected .obj, .ply, .gltf or .glb)");
}

Scene load_scene(const std::string& spec) {
    if (spec.empty()) throw Error("the scene's name is empty");
    if (spec.rfind("builtin:", 0) == 0) return make_builtin_scene(spec);
    if (!detail::file_exists(spec)) throw Error(spec + ": no such file");
    // Before the extension decides the format: a folder named without one ("." or "/tmp") would be
    // "an unknown mesh format ''".
    if (std::error_code ec; std::filesystem::is_directory(spec, ec)) throw Error(spec + ": is a folder, not a file");
    if (lower_extension(spec) == ".json") return load_view_file(spec);
    Scene scene;
    scene.name = std::filesystem::path(spec).stem().string();
    std::optional<Camera> camera;
    std::optional<float> aspect;
    if (const std::string ext = lower_extension(spec); ext == ".gltf" || ext == ".glb") {
        GltfScene gltf = load_gltf(spec);
        scene.triangles = std::move(gltf.triangles);
        camera = gltf.camera;
        aspect = gltf.aspect_ratio;
    } else {
        scene.triangles = load_mesh(spec);
    }
    if (scene.triangles.empty()) throw Error(spec + ": the mesh has no triangles");
    set_default_view(scene);
    // A glTF file's first perspective camera is its view; the light stays the default one's, and
    // the camera's aspect ratio, where given, sets the width beside the default height.
    if (camera) scene.camera = *camera;
    if (const std::string why = default_view_problem(scene, !camera); !why.empty())
        throw Error(spec + ": " + why + "; give it a view file with its own camera and light (docs/SCENES.md)");
    if (aspect)
        scene.width = static_cast<int>(std::lround(
            std::clamp(static_cast<double>(scene.height) * *aspect, 1.0, static_cast<double>(kMaxImageSide))));
    validate_scene(scene, spec);
    return scene;
}

}  // namespace cellrt
