// Pinhole camera: one primary ray per pixel through the pixel centre, as in the study.
#pragma once

#include "cellrt/ray.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/shading.hpp"

namespace cellrt {

class PinholeCamera {
public:
    // Throws cellrt::Error for an impossible camera: zero-length view direction, up parallel to it,
    // fov_y_deg outside (0, 180), non-finite values, or an image size check_image_size refuses.
    PinholeCamera(const Camera& camera, int width, int height);

    // Ray through the centre of pixel (px, py); py = 0 is the top row. Direction is normalised.
    Ray primary(int px, int py) const { return projection_.primary(px, py); }

    int width() const { return static_cast<int>(projection_.width); }
    int height() const { return static_cast<int>(projection_.height); }
    // The checked camera as plain data (shading.hpp), for the GPU's frame path.
    const PinholeProjection& projection() const { return projection_; }

private:
    PinholeProjection projection_;
};

}  // namespace cellrt
