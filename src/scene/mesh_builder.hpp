// Appends simple tessellated solids to a triangle list (internal, for the built-in scenes and
// tests). Closed solids share their vertices exactly between neighbouring triangles, so they are
// watertight meshes for the watertightness tests.
#pragma once

#include <vector>

#include "cellrt/triangle.hpp"

namespace cellrt::detail {

class MeshBuilder {
public:
    explicit MeshBuilder(std::vector<Triangle>& out) : out_(out) {}

    void triangle(const Vec3& a, const Vec3& b, const Vec3& c) { out_.push_back({a, b, c}); }
    // Quad a-b-c-d (counter-clockwise seen from its front) as two triangles.
    void quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
        triangle(a, b, c);
        triangle(a, c, d);
    }
    // Axis-aligned box, 12 triangles.
    void box(const Vec3& lo, const Vec3& hi);
    // UV sphere with `segments` around and `rings` from pole to pole (>= 3 and >= 2).
    void sphere(const Vec3& centre, float radius, int segments, int rings);

private:
    std::vector<Triangle>& out_;
};

}  // namespace cellrt::detail
