// The procedural generators behind builtin.hpp (internal). Each fills a scene's triangles, camera
// and light from a triangle budget and a seed, and nothing else: the same parameters give the same
// scene bit for bit (random numbers from random.hpp only).
#pragma once

#include <cstddef>
#include <cstdint>

#include "cellrt/scene.hpp"

namespace cellrt::detail {

struct BuiltinParams {
    std::size_t tris = 0;  // the requested triangle count; generators land within a few percent
    std::uint64_t seed = 1;
};

void make_spheres(Scene& scene, const BuiltinParams& params);
void make_city(Scene& scene, const BuiltinParams& params);
void make_forest(Scene& scene, const BuiltinParams& params);

}  // namespace cellrt::detail
