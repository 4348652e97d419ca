// A scene: triangles, a pinhole camera, one point light and an image size, loaded from a view file,
// a bare mesh (OBJ, PLY or glTF, with a default view) or a built-in procedural generator.
#pragma once

#include <string>
#include <vector>

#include "cellrt/box.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt {

struct Camera {
    Vec3 position{0.f, 0.f, 1.f};
    Vec3 look_at{0.f, 0.f, 0.f};
    Vec3 up{0.f, 1.f, 0.f};
    float fov_y_deg = 60.f;  // full vertical field of view, in (0, 180)
};

struct PointLight {
    Vec3 position{0.f, 10.f, 0.f};
    Vec3 color{1.f, 1.f, 1.f};
};

// The largest light colour channel: the shadings' sums of a few light terms (shading.hpp) stay
// finite below it; 3e38, a finite float, filled a diffuse frame with infinite pixels (found by
// audit, 2026-12-07).
inline constexpr float kMaxLightChannel = 1e30f;

// Why `color` cannot be a light's colour ("the light color has a negative channel", "... a channel
// above 1e+30"), or "" where it can.
std::string light_color_problem(const Vec3& color);

struct Scene {
    std::string name;
    std::vector<Triangle> triangles;
    Camera camera;
    PointLight light;
    int width = 512;
    int height = 512;

    Box3 bounds() const;
};

// Loads `spec`: a view file (*.json, format of shared/scenes/README.md), a mesh (*.obj, *.ply, *.gltf,
// *.glb) shown by set_default_view() (a glTF file by its first perspective camera where it has one), or `builtin:NAME[?key=value&...]` (builtin.hpp). Throws cellrt::Error with a
// message naming the file and line or the field at fault.
Scene load_scene(const std::string& spec);

// A camera looking at the whole of `bounds` from the front-upper-right and a light above it; used
// for bare meshes. A scene without triangles gets the view of the unit cube around the origin.
void set_default_view(Scene& scene);

// Why the default view that set_default_view gave `scene` (its light, and its camera too where
// `camera_too`) cannot frame its triangles in float arithmetic, as a message naming their span; ""
// where it can, or where a triangle is not finite (validate_scene names it). For a mesh around the
// origin the view fails from coordinates of about 4e18 on (the camera's distance, squared,
// overflows), and for a mesh too small for its distance from the origin.
std::string default_view_problem(const Scene& scene, bool camera_too = true);

// Checks what every loader guarantees: at least one triangle, all coordinates finite, a valid camera
// (see PinholeCamera), a finite light position, a light colour of finite, non-negative channels of at
// most kMaxLightChannel, and an image size check_image_size accepts. Throws cellrt::Error naming
// `where` otherwise.
void validate_scene(const Scene& scene, const std::string& where);

}  // namespace cellrt
