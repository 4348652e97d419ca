#include "mesh_builder.hpp"

#include <cmath>
#include <numbers>

namespace cellrt::detail {

void MeshBuilder::box(const Vec3& lo, const Vec3& hi) {
    const Vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                       {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    quad(p[0], p[3], p[2], p[1]);  // -z
    quad(p[4], p[5], p[6], p[7]);  // +z
    quad(p[0], p[4], p[7], p[3]);  // -x
    quad(p[1], p[2], p[6], p[5]);  // +x
    quad(p[0], p[1], p[5], p[4]);  // -y
    quad(p[3], p[7], p[6], p[2]);  // +y
}

void MeshBuilder::sphere(const Vec3& centre, float radius, int segments, int rings) {
    // Vertices are computed once per (ring, segment) so shared edges use identical coordinates; the
    // angles' sines and cosines in double, rounded once, as in ring().
    std::vector<Vec3> grid(static_cast<std::size_t>(rings + 1) * segments);
    for (int r = 0; r <= rings; ++r) {
        const double theta = std::numbers::pi * r / rings;
        for (int s = 0; s < segments; ++s) {
            const double phi = 2.0 * std::numbers::pi * s / segments;
            Vec3 dir{static_cast<float>(std::sin(theta) * std::cos(phi)), static_cast<float>(std::cos(theta)),
                     static_cast<float>(std::sin(theta) * std::sin(phi))};
            if (r == 0) dir = {0.f, 1.f, 0.f};
            if (r == rings) dir = {0.f, -1.f, 0.f};
            grid[static_cast<std::size_t>(r) * segments + s] = centre + dir * radius;
        }
    }
    auto at = [&](int r, int s) { return grid[static_cast<std::size_t>(r) * segments + (s % segments)]; };
    for (int r = 0; r < rings; ++r) {
        for (int s = 0; s < segments; ++s) {
            if (r > 0) triangle(at(r, s), at(r, s + 1), at(r + 1, s));
            if (r + 1 < rings) triangle(at(r, s + 1), at(r + 1, s + 1), at(r + 1, s));
        }
    }
}

void MeshBuilder::ring(const Vec3& centre, const Vec3& axis, float radius, int sides, std::vector<Vec3>& out) const {
    const Vec3 a = normalize(axis);
    const Vec3 helper = std::fabs(a.y) < 0.9f ? Vec3{0.f, 1.f, 0.f} : Vec3{1.f, 0.f, 0.f};
    const Vec3 u = normalize(cross(helper, a));
    const Vec3 w = cross(a, u);  // (u, w, a) is right-handed: the ring runs counter-clockwise seen from +a
    out.resize(static_cast<std::size_t>(sides));
    for (int k = 0; k < sides; ++k) {
        // In double, rounded once: the libm float functions are less alike between platforms.
        const double phi = 2.0 * std::numbers::pi * k / sides;
        const auto c = static_cast<float>(std::cos(phi)), s = static_cast<float>(std::sin(phi));
        out[static_cast<std::size_t>(k)] = centre + (u * c + w * s) * radius;
    }
}

void MeshBuilder::fan(const std::vector<Vec3>& polygon, bool reversed) {
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
        if (reversed) triangle(polygon[0], polygon[k + 1], polygon[k]);
        else triangle(polygon[0], polygon[k], polygon[k + 1]);
    }
}

void MeshBuilder::cone(const Vec3& base, const Vec3& apex, float radius, int sides) {
    ring(base, apex - base, radius, sides, base_ring_);
    const auto n = base_ring_.size();
    for (std::size_t k = 0; k < n; ++k) triangle(base_ring_[k], base_ring_[(k + 1) % n], apex);
    fan(base_ring_, /*reversed=*/true);
}

void MeshBuilder::frustum(const Vec3& base, const Vec3& top, float base_radius, float top_radius, int sides) {
    ring(base, top - base, base_radius, sides, base_ring_);
    ring(top, top - base, top_radius, sides, top_ring_);
    const auto n = base_ring_.size();
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t k1 = (k + 1) % n;
        quad(base_ring_[k], base_ring_[k1], top_ring_[k1], top_ring_[k]);
    }
    fan(base_ring_, /*reversed=*/true);
    fan(top_ring_, /*reversed=*/false);
}

}  // namespace cellrt::detail
