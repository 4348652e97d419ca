// Pinhole camera: one primary ray per pixel through the pixel centre, as in the study.
#pragma once

#include "cellrt/ray.hpp"
#include "cellrt/scene.hpp"

namespace cellrt {

class PinholeCamera {
public:
    // Throws cellrt::Error for an impossible camera: zero-length view direction, up parallel to it,
    // fov_y_deg outside (0, 180), non-finite values, or an image size check_image_size refuses.
    PinholeCamera(const Camera& camera, int width, int height);

    // Ray through the centre of pixel (px, py); py = 0 is the top row. Direction is normalised.
    Ray primary(int px, int py) const {
        const float sx = (2.f * (static_cast<float>(px) + 0.5f) / width_ - 1.f) * half_w_;
        const float sy = (1.f - 2.f * (static_cast<float>(py) + 0.5f) / height_) * half_h_;
        Ray r;
        r.org = origin_;
        r.dir = normalize(forward_ + right_ * sx + up_ * sy);
        return r;
    }

    int width() const { return static_cast<int>(width_); }
    int height() const { return static_cast<int>(height_); }

private:
    Vec3 origin_, forward_, right_, up_;
    float half_w_ = 0.f, half_h_ = 0.f;
    float width_ = 1.f, height_ = 1.f;
};

}  // namespace cellrt
