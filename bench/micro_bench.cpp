// Micro-benchmarks of the innermost kernels (Google Benchmark). Whole-frame figures with Embree
// alongside are in accel_bench.
#include <benchmark/benchmark.h>

#include <random>

#include "cellrt/triangle.hpp"

namespace {

using namespace cellrt;

std::vector<Triangle> random_triangles(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    std::vector<Triangle> tris(n);
    for (Triangle& t : tris) {
        const Vec3 c{u(rng), u(rng), u(rng)};
        t = {c + Vec3{u(rng), u(rng), u(rng)} * 0.3f, c + Vec3{u(rng), u(rng), u(rng)} * 0.3f,
             c + Vec3{u(rng), u(rng), u(rng)} * 0.3f};
    }
    return tris;
}

void BM_WatertightClosest(benchmark::State& state) {
    const auto tris = random_triangles(1024, 1);
    Ray ray;
    ray.org = {0.f, 0.f, -3.f};
    ray.dir = normalize(Vec3{0.01f, 0.02f, 1.f});
    const WatertightRay wr(ray);
    for (auto _ : state) {
        Hit best = miss_for(ray);
        for (std::size_t i = 0; i < tris.size(); ++i)
            intersect_closest(wr, ray.tnear, tris[i], static_cast<std::uint32_t>(i), best);
        benchmark::DoNotOptimize(best);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(tris.size()));
}
BENCHMARK(BM_WatertightClosest);

}  // namespace
