// Three-component float vector: the one numeric type of cellrt's geometry.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "cellrt/host_device.hpp"

namespace cellrt {

struct Vec3 {
    float x = 0.f, y = 0.f, z = 0.f;

    constexpr Vec3() = default;
    CELLRT_HD constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
    CELLRT_HD constexpr explicit Vec3(float s) : x(s), y(s), z(s) {}

    // Indexed read as one load from the vector itself (no chain of selects, no copy to the stack, as
    // a bit_cast to an array compiles to): the kernels index by per-ray axes. The three floats are
    // the struct's storage (Embree's Vec3 reads them the same way).
    CELLRT_HD constexpr float operator[](std::size_t i) const {
        if (std::is_constant_evaluated()) return i == 0 ? x : (i == 1 ? y : z);
        return reinterpret_cast<const float*>(this)[i];
    }
    CELLRT_HD constexpr float& operator[](std::size_t i) { return i == 0 ? x : (i == 1 ? y : z); }

    CELLRT_HD constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    CELLRT_HD constexpr Vec3& operator+=(const Vec3& b) { x += b.x; y += b.y; z += b.z; return *this; }
    CELLRT_HD constexpr Vec3& operator-=(const Vec3& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
    CELLRT_HD constexpr Vec3& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
    friend constexpr bool operator==(const Vec3&, const Vec3&) = default;
};
static_assert(sizeof(Vec3) == 12);

CELLRT_HD constexpr Vec3 operator+(Vec3 a, const Vec3& b) { return a += b; }
CELLRT_HD constexpr Vec3 operator-(Vec3 a, const Vec3& b) { return a -= b; }
CELLRT_HD constexpr Vec3 operator*(Vec3 a, float s) { return a *= s; }
CELLRT_HD constexpr Vec3 operator*(float s, Vec3 a) { return a *= s; }
CELLRT_HD constexpr Vec3 operator*(const Vec3& a, const Vec3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
CELLRT_HD constexpr Vec3 operator/(const Vec3& a, float s) { return {a.x / s, a.y / s, a.z / s}; }

CELLRT_HD constexpr float dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
CELLRT_HD constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
CELLRT_HD inline float length(const Vec3& a) { return std::sqrt(dot(a, a)); }
CELLRT_HD inline Vec3 normalize(const Vec3& a) { return a * (1.f / length(a)); }
CELLRT_HD inline Vec3 min(const Vec3& a, const Vec3& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
CELLRT_HD inline Vec3 max(const Vec3& a, const Vec3& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
CELLRT_HD inline Vec3 abs(const Vec3& a) { return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}; }
// The largest of |x|, |y|, |z| (NaN-free inputs).
CELLRT_HD inline float max_magnitude(const Vec3& a) { return std::fmax(std::fabs(a.x), std::fmax(std::fabs(a.y), std::fabs(a.z))); }
CELLRT_HD inline bool is_finite(const Vec3& a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
// Index of the component with the largest magnitude (ties: lowest index).
CELLRT_HD inline int max_axis(const Vec3& a) {
    const Vec3 m = abs(a);
    return m.x >= m.y ? (m.x >= m.z ? 0 : 2) : (m.y >= m.z ? 1 : 2);
}

}  // namespace cellrt
