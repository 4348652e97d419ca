// Appends simple tessellated solids to a triangle list (internal, for the built-in scenes and
// tests). Closed solids share their vertices exactly between neighbouring triangles, so they are
// watertight meshes for the watertightness tests.
#pragma once

#include <cstddef>
#include <vector>

#include "cellrt/triangle.hpp"

namespace cellrt::detail {

class MeshBuilder {
public:
    explicit MeshBuilder(std::vector<Triangle>& out) : out_(out) {}

    // Triangles each solid appends, for the scenes' triangle budgets.
    static constexpr std::size_t kBoxTriangles = 12;
    static constexpr std::size_t cone_triangles(int sides) { return 2 * static_cast<std::size_t>(sides) - 2; }
    static constexpr std::size_t frustum_triangles(int sides) { return 4 * static_cast<std::size_t>(sides) - 4; }

    void triangle(const Vec3& a, const Vec3& b, const Vec3& c) { out_.push_back({a, b, c}); }
    // Quad a-b-c-d (counter-clockwise seen from its front) as two triangles.
    void quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
        triangle(a, b, c);
        triangle(a, c, d);
    }
    // Axis-aligned box, kBoxTriangles triangles.
    void box(const Vec3& lo, const Vec3& hi);
    // UV sphere with `segments` around and `rings` from pole to pole (>= 3 and >= 2).
    void sphere(const Vec3& centre, float radius, int segments, int rings);
    // Closed cone: a `sides`-gon (>= 3) of `radius` around `base`, perpendicular to apex - base, joined
    // to `apex`; cone_triangles(sides) triangles.
    void cone(const Vec3& base, const Vec3& apex, float radius, int sides);
    // Closed truncated cone from a `sides`-gon (>= 3) of `base_radius` around `base` to one of
    // `top_radius` around `top` (a cylinder when the radii are equal); frustum_triangles(sides) triangles.
    void frustum(const Vec3& base, const Vec3& top, float base_radius, float top_radius, int sides);

private:
    // The regular `sides`-gon of `radius` around `centre` in the plane perpendicular to `axis`.
    void ring(const Vec3& centre, const Vec3& axis, float radius, int sides, std::vector<Vec3>& out) const;
    // Fan over a convex polygon given counter-clockwise from the side it faces.
    void fan(const std::vector<Vec3>& polygon, bool reversed);

    std::vector<Triangle>& out_;
    std::vector<Vec3> base_ring_, top_ring_;  // reused by cone and frustum
};

}  // namespace cellrt::detail
