#include "cellrt/camera.hpp"

#include <cmath>
#include <numbers>

#include "cellrt/error.hpp"
#include "cellrt/image.hpp"

namespace cellrt {

PinholeCamera::PinholeCamera(const Camera& camera, int width, int height) {
    check_image_size(width, height);
    if (!is_finite(camera.position) || !is_finite(camera.look_at) || !is_finite(camera.up))
        throw Error("camera position, look_at and up must be finite");
    if (!(camera.fov_y_deg > 0.f && camera.fov_y_deg < 180.f))
        throw Error("camera fov_y_deg = " + std::to_string(camera.fov_y_deg) + " must lie in (0, 180)");
    const Vec3 view = camera.look_at - camera.position;
    if (!(length(view) > 0.f)) throw Error("camera look_at equals position: the view direction has zero length");
    if (!(length(camera.up) > 0.f)) throw Error("camera up has zero length");
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
