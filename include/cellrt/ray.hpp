// Rays and hit records, and the one hit rule every acceleration structure obeys.
//
// Hit rule (docs/HIT_SEMANTICS.md): the hit of a ray is the triangle with the smallest t such that
// tnear <= t <= tfar, where t is the value the watertight test (triangle.hpp) computes; among
// triangles with equal t the lowest index wins. Any-hit (occlusion) asks only whether such a
// triangle exists. A ray with a non-finite or zero direction (or one whose components are all
// subnormal, below 2^-126: the watertight test divides by the largest), a non-finite origin, a NaN
// bound, tnear > tfar or tnear = +inf hits nothing. A subnormal component of a valid ray's
// direction is taken as zero of its sign (traced_direction). Because the rule names one triangle,
// the image never depends on the structure or on the order in which a traversal visits its nodes.
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
inline constexpr float kLeastSubnormal = 0x1p-149f;

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

// The direction every path traces: a subnormal component (below 2^-126, not zero) taken as zero of
// its sign. Its reciprocal, which the box and cell tests multiply by, overflows to infinity below
// about 2.9e-39, and (lo - org) * inf is then infinite where the true distance (lo - org) / d is
// finite: every structure missed a triangle 1e-35 off the axis 1.5e5 along it, which brute force
// and Embree hit (found by review, 2026-12-06). With the component zero, every path, brute force
// included, traces the axis-parallel ray that the tests' axis-parallel rays check; a subnormal
// component moves a ray by less than 2^-126 per unit of t, which only geometry that thin sees.
// A valid ray's direction with no component below 2^-126 is returned as it is after one test of
// the least magnitude; a zero component counts as below and takes the per-component path, which
// leaves it as it is. (A NaN may pass the test: invalid rays, which never reach a traversal.)
// Measured on a kd-tree's single rays, the set-up costs 20 to 30 instructions a ray all the same
// (callgrind: docs/INCOHERENT.md, eighteenth round).
CELLRT_HD inline float traced_component(float d) { return std::fabs(d) < kLeastNormal ? std::copysign(0.f, d) : d; }
CELLRT_HD inline Vec3 traced_direction(const Ray& r) {
    const float x = std::fabs(r.dir.x), y = std::fabs(r.dir.y), z = std::fabs(r.dir.z);
    const float xy = x < y ? x : y;
    if (!((xy < z ? xy : z) < kLeastNormal)) [[likely]] return r.dir;
    return {traced_component(r.dir.x), traced_component(r.dir.y), traced_component(r.dir.z)};
}

// The initial best of a closest-hit query: nothing found, any t up to tfar still admissible.
CELLRT_HD inline Hit miss_for(const Ray& r) { return Hit{r.tfar, kNoHit, 0.f, 0.f}; }

}  // namespace cellrt
