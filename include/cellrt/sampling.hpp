// Deterministic random numbers and the cosine-weighted hemisphere, for the rays of the AO and diffuse
// workloads. A number is a hash of what it is for (a pixel, a sample, a dimension), not a step of a
// generator: the rays of a pixel are the same whatever the packet size, the order in which workers
// take packets or the number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "cellrt/host_device.hpp"
#include "cellrt/vec.hpp"

namespace cellrt {

// SplitMix64's finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
// OOPSLA 2014): a bijection on 64 bits that mixes every input bit into every output bit.
CELLRT_HD constexpr std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// A float in [0, 1) from the top 24 bits of a hash: every value is exact and equally likely.
CELLRT_HD constexpr float unit_float(std::uint64_t bits) {
    return static_cast<float>(bits >> 40) * (1.f / static_cast<float>(1u << 24));
}

// The uniform number for dimension `dim` of sample `sample` of item `item` (a pixel, say).
CELLRT_HD constexpr float hash_uniform(std::uint64_t item, std::uint32_t sample, std::uint32_t dim) {
    return unit_float(mix64(mix64(item * 0x9e3779b97f4a7c15ull + sample) ^ (std::uint64_t{dim} << 32 | 0x5bd1e995u)));
}

// cos and sin of the angle 2 pi u, for u in [0, 1) with 24 bits (unit_float's), from +, - and *
// alone: the same bits on the host and on the GPU, whose cosf and sinf round differently from the C
// library's. The octant of the turn and the offset within it are exact (u * 8 scales by a power of
// two, and the offset keeps u's 24 bits); Taylor polynomials to the ninth and tenth degree on
// [0, pi / 4] then leave an error of about 2^-24; the octant's symmetries give the rest.
CELLRT_HD inline void cos_sin_turns(float u, float& c, float& s) {
    const float t = u * 8.f;
    const int octant = static_cast<int>(t) & 7;
    const float f = t - static_cast<float>(static_cast<int>(t));  // in [0, 1), exact
    // Odd octants measure from the octant's far end: the angle within the quadrant is pi/2 - x.
    const float x = ((octant & 1) ? 1.f - f : f) * (std::numbers::pi_v<float> / 4.f);
    const float x2 = x * x;
    const float sin_x = x * (1.f + x2 * (-1.f / 6.f + x2 * (1.f / 120.f + x2 * (-1.f / 5040.f + x2 * (1.f / 362880.f)))));
    const float cos_x =
        1.f + x2 * (-0.5f + x2 * (1.f / 24.f + x2 * (-1.f / 720.f + x2 * (1.f / 40320.f + x2 * (-1.f / 3628800.f)))));
    const float cq = (octant & 1) ? sin_x : cos_x, sq = (octant & 1) ? cos_x : sin_x;  // within the quadrant
    switch (octant >> 1) {
        case 0: c = cq; s = sq; break;
        case 1: c = -sq; s = cq; break;
        case 2: c = -cq; s = -sq; break;
        default: c = sq; s = -cq; break;
    }
}

// A direction about the unit normal `n`, with density cos(theta) / pi, from two uniform numbers
// (Malley's method: a uniform point on the disc lifted to the hemisphere). The frame about n is
// Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017: no division by a
// component that can vanish. The result has unit length up to rounding and never points below the
// surface (z >= 0 in the frame). The same bits on the host and the GPU (cos_sin_turns).
CELLRT_HD inline Vec3 cosine_hemisphere(const Vec3& n, float u1, float u2) {
    const float sign = std::copysign(1.f, n.z);
    const float a = -1.f / (sign + n.z), b = n.x * n.y * a;
    const Vec3 t{1.f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    const Vec3 s{b, sign + n.y * n.y * a, -n.y};
    float cos_phi = 1.f, sin_phi = 0.f;
    cos_sin_turns(u2, cos_phi, sin_phi);
    const float r = std::sqrt(u1);
    const float z = std::sqrt(std::max(0.f, 1.f - u1));
    return t * (r * cos_phi) + s * (r * sin_phi) + n * z;
}

}  // namespace cellrt
