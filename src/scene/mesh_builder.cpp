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
    const float pi = std::numbers::pi_v<float>;
    // Vertices are computed once per (ring, segment) so shared edges use identical coordinates.
    std::vector<Vec3> grid(static_cast<std::size_t>(rings + 1) * segments);
    for (int r = 0; r <= rings; ++r) {
        const float theta = pi * static_cast<float>(r) / static_cast<float>(rings);
        for (int s = 0; s < segments; ++s) {
            const float phi = 2.f * pi * static_cast<float>(s) / static_cast<float>(segments);
            Vec3 dir{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
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

}  // namespace cellrt::detail
