// Deterministic random numbers and the cosine-weighted hemisphere, for the rays of the AO and diffuse
// workloads. A number is a hash of what it is for (a pixel, a sample, a dimension), not a step of a
// generator: the rays of a pixel are the same whatever the packet size, the order in which workers
// take packets or the number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "cellrt/vec.hpp"

namespace cellrt {

// SplitMix64's finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
// OOPSLA 2014): a bijection on 64 bits that mixes every input bit into every output bit.
constexpr std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// A float in [0, 1) from the top 24 bits of a hash: every value is exact and equally likely.
constexpr float unit_float(std::uint64_t bits) {
    return static_cast<float>(bits >> 40) * (1.f / static_cast<float>(1u << 24));
}

// The uniform number for dimension `dim` of sample `sample` of item `item` (a pixel, say).
constexpr float hash_uniform(std::uint64_t item, std::uint32_t sample, std::uint32_t dim) {
    return unit_float(mix64(mix64(item * 0x9e3779b97f4a7c15ull + sample) ^ (std::uint64_t{dim} << 32 | 0x5bd1e995u)));
}

// A direction about the unit normal `n`, with density cos(theta) / pi, from two uniform numbers
// (Malley's method: a uniform point on the disc lifted to the hemisphere). The frame about n is
// Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017: no division by a
// component that can vanish. The result has unit length up to rounding and never points below the
// surface (z >= 0 in the frame).
inline Vec3 cosine_hemisphere(const Vec3& n, float u1, float u2) {
    const float sign = std::copysign(1.f, n.z);
    const float a = -1.f / (sign + n.z), b = n.x * n.y * a;
    const Vec3 t{1.f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    const Vec3 s{b, sign + n.y * n.y * a, -n.y};
    const float r = std::sqrt(u1), phi = 2.f * std::numbers::pi_v<float> * u2;
    const float z = std::sqrt(std::max(0.f, 1.f - u1));
    return t * (r * std::cos(phi)) + s * (r * std::sin(phi)) + n * z;
}

}  // namespace cellrt
