#include "cellrt/camera.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "cellrt/error.hpp"
#include "cellrt/image.hpp"

namespace cellrt {

PinholeCamera::PinholeCamera(const Camera& camera, int width, int height) {
    check_image_size(width, height);
    if (!is_finite(camera.position) || !is_finite(camera.look_at) || !is_finite(camera.up))
        throw Error("camera position, look_at and up must be finite");
    if (!(camera.fov_y_deg > 0.f && camera.fov_y_deg < 180.f)) {
        char text[96];
        std::snprintf(text, sizeof text, "camera fov_y_deg = %.9g must lie in (0, 180)", double{camera.fov_y_deg});
        throw Error(text);
    }
    // Lengths are taken in float, where the square of a length overflows from about 1.8e19 and
    // underflows to zero below about 4e-23: such a view direction or up could not be normalised, and
    // was reported as "up is parallel to the view direction" or as a zero length it did not have.
    const auto exact_length = [](const Vec3& a, const Vec3& b) {
        const double x = double{a.x} - b.x, y = double{a.y} - b.y, z = double{a.z} - b.z;
        return std::sqrt(x * x + y * y + z * z);
    };
    const auto out_of_range = [](const std::string& what, double l) {
        char text[160];
        std::snprintf(text, sizeof text, "camera %s is %.6g: float arithmetic takes lengths from about 4e-23 to 1.8e19",
                      what.c_str(), l);
        return Error(text);
    };
    const Vec3 view = camera.look_at - camera.position;
    if (camera.look_at.x == camera.position.x && camera.look_at.y == camera.position.y &&
        camera.look_at.z == camera.position.z)
        throw Error("camera look_at equals position: the view direction has zero length");
    if (const float l = length(view); !(l > 0.f && l < kInfinity))
        throw out_of_range("look_at's distance from position", exact_length(camera.look_at, camera.position));
    if (camera.up.x == 0.f && camera.up.y == 0.f && camera.up.z == 0.f) throw Error("camera up has zero length");
    if (const float l = length(camera.up); !(l > 0.f && l < kInfinity))
        throw out_of_range("up's length", exact_length(camera.up, Vec3{0.f, 0.f, 0.f}));
    PinholeProjection& p = projection_;
    p.forward = normalize(view);
    const Vec3 side = cross(p.forward, camera.up);
    // sin of the angle between up and the view direction; below ~1e-4 rad the basis is meaningless.
    if (!(length(side) > 1e-4f * length(camera.up))) throw Error("camera up is parallel to the view direction");
    p.right = normalize(side);
    p.up = cross(p.right, p.forward);
    p.origin = camera.position;
    p.half_h = std::tan(0.5f * camera.fov_y_deg * std::numbers::pi_v<float> / 180.f);
    p.half_w = p.half_h * static_cast<float>(width) / static_cast<float>(height);
    p.width = static_cast<float>(width);
    p.height = static_cast<float>(height);
}

}  // namespace cellrt
