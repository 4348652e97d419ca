// How far a hit lies from its triangle, measured in quadruple precision: for the tests of the
// triangle test's ill-conditioned hits (test_watertight.cpp) and the figure that set their threshold
// (docs/figures/exact_hits_2026-12-07/float_t_error.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "cellrt/ray.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt::test {

// The distance from p to the triangle (Ericson, Real-Time Collision Detection, section 5.1.5), in
// quadruple precision where the compiler has it: its differences of products cancel as a sliver's
// aspect squared (2^45 for 12 by 2e-6), which left double a few bits and long double too few.
#if defined(__SIZEOF_FLOAT128__)
using Real = __float128;
#else
using Real = long double;
#endif
using R3 = std::array<Real, 3>;
inline Real distance_to(const Triangle& tri, const R3& p) {
    const auto of = [](const Vec3& v) { return R3{v.x, v.y, v.z}; };
    const auto sub = [](const R3& a, const R3& b) { return R3{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
    const auto dot3 = [](const R3& a, const R3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const auto at = [](const R3& a, const R3& d, Real s) { return R3{a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]}; };
    const R3 a = of(tri.v0), b = of(tri.v1), c = of(tri.v2), ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    auto nearest = [&]() -> R3 {
        const Real d1 = dot3(ab, ap), d2 = dot3(ac, ap);
        if (d1 <= 0 && d2 <= 0) return a;
        const R3 bp = sub(p, b);
        const Real d3 = dot3(ab, bp), d4 = dot3(ac, bp);
        if (d3 >= 0 && d4 <= d3) return b;
        const Real vc = d1 * d4 - d3 * d2;
        if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(a, ab, d1 / (d1 - d3));
        const R3 cp = sub(p, c);
        const Real d5 = dot3(ab, cp), d6 = dot3(ac, cp);
        if (d6 >= 0 && d5 <= d6) return c;
        const Real vb = d5 * d2 - d1 * d6;
        if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(a, ac, d2 / (d2 - d6));
        const Real va = d3 * d6 - d5 * d4;
        if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return at(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
        const Real denom = va + vb + vc;
        if (!(denom != 0)) return a;
        return at(at(a, ab, vb / denom), ac, vc / denom);
    };
    const R3 q = sub(p, nearest());
    return Real(std::sqrt(static_cast<long double>(dot3(q, q))));
}

// The triangle's largest offset from the ray's origin.
inline Real widest_offset(const Triangle& tri, const Ray& ray) {
    Real widest = 0;
    for (const Vec3& v : {tri.v0, tri.v1, tri.v2})
        for (int axis = 0; axis < 3; ++axis) widest = std::max(widest, Real(std::fabs(double(v[axis]) - ray.org[axis])));
    return widest;
}

// How far from the triangle a hit at t lies, over the triangle's largest offset from the origin.
inline Real relative_miss(const Triangle& tri, const Ray& ray, float t) {
    R3 p;
    for (int axis = 0; axis < 3; ++axis) p[axis] = Real(ray.org[axis]) + Real(t) * ray.dir[axis];
    return distance_to(tri, p) / widest_offset(tri, ray);
}

// How far the point the barycentrics name lies from the point at t, over the same.
inline Real relative_uv_gap(const Triangle& tri, const Ray& ray, float t, float u, float v) {
    Real gap2 = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const Real named = (1 - Real(u) - Real(v)) * tri.v0[axis] + Real(u) * tri.v1[axis] + Real(v) * tri.v2[axis];
        const Real d = named - (Real(ray.org[axis]) + Real(t) * ray.dir[axis]);
        gap2 += d * d;
    }
    return Real(std::sqrt(static_cast<long double>(gap2))) / widest_offset(tri, ray);
}

}  // namespace cellrt::test
