// Slivers and the rays aimed at them, for the tests of the triangle test's ill-conditioned hits
// (test_watertight.cpp) and the figure that set their threshold
// (docs/figures/exact_hits_2026-12-07/float_t_error.cpp): one generator, so that the figure measured
// the triangles and rays the tests hold the test to.
#pragma once

#include <random>

#include "cellrt/ray.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt::test {

// A sliver: a corner in [0, 4)^3, a second one `length` along a random direction, and a third on
// the edge between them moved by up to `width()` (called after the second corner is drawn) across it.
template <class Width>
Triangle random_sliver(std::mt19937& rng, float length, Width&& width) {
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    const Vec3 a{u01(rng) * 4, u01(rng) * 4, u01(rng) * 4};
    const Vec3 b = a + Vec3{u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f} * length;
    const float across = width();
    const Vec3 c = a + (b - a) * u01(rng) + Vec3{u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f} * across;
    return {a, b, c};
}

// A ray from up to 8 away toward a random point of `tri`; where `grazing`, its origin is moved toward
// the triangle's plane until `gap()` of its height over the plane is left, so that it grazes it.
template <class Gap>
Ray ray_onto(const Triangle& tri, std::mt19937& rng, bool grazing, Gap&& gap) {
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    const Vec3 normal = normalize(tri.geometric_normal());
    const float w0 = u01(rng), w1 = u01(rng) * (1.f - w0);
    const Vec3 target = tri.v0 * w0 + tri.v1 * w1 + tri.v2 * (1.f - w0 - w1);
    Vec3 from = target + Vec3{u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f} * 16.f;
    if (grazing) from = from - normal * (dot(from - target, normal) * (1.f - gap()));
    return Ray{from, 0.f, target - from, kInfinity};
}

}  // namespace cellrt::test
