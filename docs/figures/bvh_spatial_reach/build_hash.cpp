#include <chrono>
#include <cstdio>
#include <cstdlib>
#include "cellrt/scene.hpp"
#include "bvh/bvh_build.hpp"
using namespace cellrt;
static std::uint64_t fnv(const void* p, std::size_t n, std::uint64_t h) {
    auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}
int main(int argc, char** argv) {
    Scene s = load_scene(argv[1]);
    detail::BvhBuildOptions o;
    o.threads = 1;
    int reps = argc > 2 ? std::atoi(argv[2]) : 1;
    if (argc > 3) o.split_budget = std::atof(argv[3]);
    double best = 1e30; detail::BvhTree t;
    for (int r = 0; r < reps; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        t = detail::build_bvh(s.triangles, o);
        best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::uint64_t h = fnv(t.nodes.data(), t.nodes.size() * sizeof(t.nodes[0]), 1469598103934665603ull);
    h = fnv(t.leaves.data(), t.leaves.size() * sizeof(t.leaves[0]), h);
    std::printf("%s sah %.4f refs %zu hash %016llx min_ms %.1f\n", argv[1], t.sah_cost, t.references, (unsigned long long)h, best);
}
