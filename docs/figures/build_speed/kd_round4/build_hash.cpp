#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include "cellrt/scene.hpp"
#include "kdtree/kd_tree.hpp"
#include "kdtree/kd_sah.hpp"
using namespace cellrt;
static std::uint64_t fnv(const void* p, std::size_t n, std::uint64_t h) {
    auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}
int main(int argc, char** argv) {
    // usage: kdb SCENE REPEATS THREADS [clip_ratio max_bad_refines]
    Scene s = load_scene(argv[1]);
    int reps = std::atoi(argv[2]);
    detail::KdBuildParams p;
    p.threads = std::atoi(argv[3]);
    if (argc > 5) { p.clip_ratio = std::atof(argv[4]); p.max_bad_refines = std::atoi(argv[5]); }
    double best = 1e30;
    std::uint64_t h = 0;
    std::size_t nodes = 0;
    for (int r = 0; r < reps; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        detail::KdTree t = detail::build_kdtree(s.triangles, p);
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        best = std::min(best, ms);
        h = fnv(t.nodes.data(), t.nodes.size() * sizeof(t.nodes[0]), 1469598103934665603ull);
        h = fnv(t.indices.data(), t.indices.size() * 4, h);
        nodes = t.nodes.size();
    }
    std::printf("%s nodes %zu hash %016llx min_ms %.1f\n", argv[1], nodes, (unsigned long long)h, best);
}
