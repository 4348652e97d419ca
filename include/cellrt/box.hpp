// Axis-aligned bounding box. An empty box has lo = +inf, hi = -inf so that extend() needs no branch.
#pragma once

#include <limits>

#include "cellrt/vec.hpp"

namespace cellrt {

struct Box3 {
    Vec3 lo{std::numeric_limits<float>::infinity()};
    Vec3 hi{-std::numeric_limits<float>::infinity()};

    static Box3 empty() { return {}; }
    bool is_empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    void extend(const Vec3& p) { lo = min(lo, p); hi = max(hi, p); }
    void extend(const Box3& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
    Vec3 extent() const { return hi - lo; }
    Vec3 center() const { return (lo + hi) * 0.5f; }
    // Surface area; 0 for an empty or flat-in-two-axes box.
    float area() const {
        if (is_empty()) return 0.f;
        const Vec3 e = extent();
        return 2.f * (e.x * e.y + e.y * e.z + e.z * e.x);
    }
    bool contains(const Vec3& p) const {
        return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
    }
    friend bool operator==(const Box3&, const Box3&) = default;
};

inline Box3 intersection(const Box3& a, const Box3& b) { return {max(a.lo, b.lo), min(a.hi, b.hi)}; }

}  // namespace cellrt
