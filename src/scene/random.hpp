// The pseudo-random numbers of the built-in scenes (internal). SplitMix64 (Steele, Lea, Flood: "Fast
// splittable pseudorandom number generators", OOPSLA 2014) and float conversions written out here, not
// std::uniform_*_distribution, whose algorithms differ between standard libraries: a scene must be the
// same triangles on every machine.
#pragma once

#include <cstdint>

namespace cellrt::detail {

class SplitMix64 {
public:
    explicit SplitMix64(std::uint64_t seed) : state_(seed) {}

    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }

    // Uniform in [0, 1): the top 24 bits, which a float holds exactly.
    float uniform() { return static_cast<float>(next() >> 40) * 0x1p-24f; }
    float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
    // Uniform integer in [lo, hi] (multiply-shift; the bias of at most (hi - lo + 1) / 2^32 is irrelevant here).
    int integer(int lo, int hi) {
        const auto span = static_cast<std::uint64_t>(hi - lo + 1);
        return lo + static_cast<int>(((next() >> 32) * span) >> 32);
    }

private:
    std::uint64_t state_;
};

// A random value in [0, 1) attached to an integer lattice point, for value noise: the same point and
// seed always give the same value, without storing the lattice.
inline float lattice_value(std::uint64_t seed, std::int64_t i, std::int64_t j) {
    SplitMix64 rng(seed ^ (static_cast<std::uint64_t>(i) * 0x8cb92ba72f3d8dd7ull) ^
                   (static_cast<std::uint64_t>(j) * 0xd6e8feb86659fd93ull));
    return rng.uniform();
}

}  // namespace cellrt::detail
