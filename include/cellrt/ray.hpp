// Rays and hit records, and the one hit rule every acceleration structure obeys.
//
// Hit rule (docs/HIT_SEMANTICS.md): the hit of a ray is the triangle with the smallest t such that
// tnear <= t <= tfar, where t is the value the watertight test (triangle.hpp) computes; among
// triangles with equal t the lowest index wins. Any-hit (occlusion) asks only whether such a
// triangle exists. A ray with a non-finite or zero direction (or one whose components are all
// subnormal, below 2^-126: the watertight test divides by the largest), a non-finite origin, a NaN
// bound, tnear > tfar or tnear = +inf hits nothing. Because the rule names one triangle, the image
// never depends on the structure or on the order in which a traversal visits its nodes.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "cellrt/host_device.hpp"
#include "cellrt/vec.hpp"

namespace cellrt {

inline constexpr std::uint32_t kNoHit = std::numeric_limits<std::uint32_t>::max();
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();
inline constexpr float kLargestFloat = std::numeric_limits<float>::max();
inline constexpr float kLeastNormal = std::numeric_limits<float>::min();  // 2^-126

struct Ray {
    Vec3 org;
    float tnear = 0.f;
    Vec3 dir;
    float tfar = kInfinity;
};
static_assert(sizeof(Ray) == 32);

struct Hit {
    float t = kInfinity;
    std::uint32_t prim = kNoHit;  // triangle index, kNoHit for a miss
    float u = 0.f, v = 0.f;       // barycentrics: point = (1-u-v)*v0 + u*v1 + v*v2

    CELLRT_HD bool is_hit() const { return prim != kNoHit; }
    friend bool operator==(const Hit&, const Hit&) = default;
};
static_assert(sizeof(Hit) == 16);

// True when (t, prim) is preferred to `best` under the hit rule (ties: lower index).
CELLRT_HD inline bool closer(float t, std::uint32_t prim, const Hit& best) {
    return t < best.t || (t == best.t && prim < best.prim);
}

[[gnu::always_inline]] CELLRT_HD inline bool is_valid(const Ray& r) {
    return is_finite(r.org) && is_finite(r.dir) &&
           (std::fabs(r.dir.x) >= kLeastNormal || std::fabs(r.dir.y) >= kLeastNormal ||
            std::fabs(r.dir.z) >= kLeastNormal) &&
           !(r.tnear > r.tfar) && r.tnear < kInfinity && r.tfar == r.tfar;
}

// The initial best of a closest-hit query: nothing found, any t up to tfar still admissible.
CELLRT_HD inline Hit miss_for(const Ray& r) { return Hit{r.tfar, kNoHit, 0.f, 0.f}; }

}  // namespace cellrt
