// Outward rounding from double to float, for builders that compute clipped geometry in double
// precision and must keep its float boxes conservative (the kd-tree's perfect splits, the wide BVH's
// spatial splits).
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace cellrt::detail {

// std::nextafter(f, -inf) and std::nextafter(f, +inf), without the library call (which takes a
// third of the kd-tree's clipping time).
inline float float_step_down(float f) {
    if (f == 0.f) return -std::numeric_limits<float>::denorm_min();
    if (std::isnan(f) || f == -std::numeric_limits<float>::infinity()) return f;
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0.f ? bits - 1 : bits + 1);
}
inline float float_step_up(float f) { return -float_step_down(-f); }

// Rounds a double down / up to the next float, then one more float step outward. The common case,
// a float at least three steps from zero and from infinity, steps on its bits (a magnitude's bits
// count its steps from zero); near zero, near or at infinity, or NaN, the steps above decide.
inline float float_below(double x) {
    const float f = static_cast<float>(x);
    const auto steps = 1u + static_cast<std::uint32_t>(static_cast<double>(f) > x);
    const auto bits = std::bit_cast<std::uint32_t>(f);
    constexpr std::uint32_t kNear = 3, kFar = 0x7f800000u - 2;  // magnitudes [kNear, kFar): no special value within two steps
    if ((bits & 0x7fffffffu) - kNear < kFar - kNear) return std::bit_cast<float>(bits >> 31 ? bits + steps : bits - steps);
    return float_step_down(steps == 2 ? float_step_down(f) : f);
}
inline float float_above(double x) { return -float_below(-x); }

}  // namespace cellrt::detail
