// Builds a kd-tree, a BIH or a wide BVH of a scene and prints an FNV-1a hash of the tree's bytes, its size
// and the best build time: the check that a builder's refactor keeps its trees. Linked once with
// each checkout's builder, e.g. (for the kd-tree; src/bih/bih_build.cpp, src/bvh/bvh_build.cpp):
//   g++ -I include -I src -O3 -DNDEBUG -ffp-contract=off -std=c++20 docs/figures/tree_hash.cpp
//       src/kdtree/kd_build.cpp build/libcellrt.a -ltbb -lembree3 -o tree_hash
//   ./tree_hash kd|bih|bih-sah|bvh SCENE REPEATS THREADS [clip_ratio max_bad_refines | split_budget]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bih/bih_tree.hpp"
#include "bvh/bvh_build.hpp"
#include "cellrt/scene.hpp"
#include "kdtree/kd_tree.hpp"

using namespace cellrt;

static std::uint64_t fnv(const void* p, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

template <class Build>
static double best_of(int repeats, Build&& build) {
    double best = 1e30;
    for (int r = 0; r < repeats; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        build();
        best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    return best;
}

int main(int argc, char** argv) {
    if (argc < 5) return std::fprintf(stderr, "usage: tree_hash kd|bih|bih-sah|bvh SCENE REPEATS THREADS [params]\n"), 2;
    const std::string kind = argv[1];
    const Scene scene = load_scene(argv[2]);
    const int repeats = std::atoi(argv[3]);
    const auto threads = static_cast<unsigned>(std::atoi(argv[4]));
    if (kind == "kd") {
        detail::KdBuildParams p;
        p.threads = threads;
        if (argc > 6) p.clip_ratio = std::atof(argv[5]), p.max_bad_refines = std::atoi(argv[6]);
        detail::KdTree t;
        const double ms = best_of(repeats, [&] { t = detail::build_kdtree(scene.triangles, p); });
        const std::uint64_t h = fnv(t.indices.data(), t.indices.size() * 4, fnv(t.nodes.data(), t.nodes.size() * sizeof(t.nodes[0])));
        std::printf("%s nodes %zu hash %016llx min_ms %.1f\n", argv[2], t.nodes.size(), (unsigned long long)h, ms);
    } else if (kind == "bih" || kind == "bih-sah") {
        detail::BihBuildParams p;
        p.threads = threads;
        if (kind == "bih-sah") p.split = detail::BihSplit::sah;
        detail::BihTree t;
        const double ms = best_of(repeats, [&] { t = detail::build_bih(scene.triangles, p); });
        const std::uint64_t h = fnv(t.prims.data(), t.prims.size() * 4, fnv(t.nodes.data(), t.nodes.size() * sizeof(t.nodes[0])));
        std::printf("%s nodes %zu hash %016llx min_ms %.1f\n", argv[2], t.nodes.size(), (unsigned long long)h, ms);
    } else {
        detail::BvhBuildOptions o;
        o.threads = threads;
        if (argc > 5) o.split_budget = std::atof(argv[5]);
        detail::BvhTree t;
        const double ms = best_of(repeats, [&] { t = detail::build_bvh(scene.triangles, o); });
        const std::uint64_t h = fnv(t.leaves.data(), t.leaves.size() * sizeof(t.leaves[0]), fnv(t.nodes.data(), t.nodes.size() * sizeof(t.nodes[0])));
        std::printf("%s sah %.4f refs %zu hash %016llx min_ms %.1f\n", argv[2], t.sah_cost, t.references, (unsigned long long)h, ms);
    }
}
