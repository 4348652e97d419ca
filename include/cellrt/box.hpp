// Axis-aligned bounding box. An empty box has lo = +inf, hi = -inf so that extend() needs no branch.
#pragma once

#include <limits>

#include "cellrt/host_device.hpp"
#include "cellrt/vec.hpp"

namespace cellrt {

struct Box3 {
    Vec3 lo{std::numeric_limits<float>::infinity()};
    Vec3 hi{-std::numeric_limits<float>::infinity()};

    CELLRT_HD static Box3 empty() { return {}; }
    CELLRT_HD bool is_empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    CELLRT_HD void extend(const Vec3& p) { lo = min(lo, p); hi = max(hi, p); }
    CELLRT_HD void extend(const Box3& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
    CELLRT_HD Vec3 extent() const { return hi - lo; }
    CELLRT_HD Vec3 center() const { return (lo + hi) * 0.5f; }
    // Surface area; 0 for an empty or flat-in-two-axes box.
    CELLRT_HD float area() const {
        if (is_empty()) return 0.f;
        const Vec3 e = extent();
        return 2.f * (e.x * e.y + e.y * e.z + e.z * e.x);
    }
    CELLRT_HD bool contains(const Vec3& p) const {
        return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
    }
    friend bool operator==(const Box3&, const Box3&) = default;
};

CELLRT_HD inline Box3 intersection(const Box3& a, const Box3& b) { return {max(a.lo, b.lo), min(a.hi, b.hi)}; }

}  // namespace cellrt
