// The parallelism a SAH BIH build's task tree allows, read off the finished tree: work and span in
// triangle passes (docs/BUILD_SPEED.md, "The BIH's empty-space cuts as tasks"). Each node of n
// triangles costs n (its decision: a binning pass and a partition pass over its range); a node binned
// by several threads (n >= parallel_pass_min) puts only its partition, n / 2, on the span. Below
// 4,096 triangles (bih_build.cpp's kParallelMin) a subtree is one task: its span is its work. At a
// split of a larger node the two children are tasks; at an empty-space cut (one child an empty leaf)
// the occupied child is a task of its own (since 2026-12-05), and before it ran in its
// parent's task to the bottom. Work / span bounds the speed-up on any number of threads.
//   g++ -I include -I src -O2 -std=c++20 docs/figures/bih_span.cpp build/libcellrt.a -ltbb -lembree3 -o bih_span
//   ./bih_span SCENE...
#include <algorithm>
#include <cstdio>
#include <utility>

#include "bih/bih_tree.hpp"
#include "cellrt/scene.hpp"

using namespace cellrt;

namespace {

constexpr double kParallelMin = 4096;

struct Walk {
    const detail::BihTree& tree;
    double pass_min;

    double triangles(std::uint32_t i) const {
        const detail::BihNode& n = tree.nodes[i];
        if (n.is_leaf()) return n.count();
        return triangles(n.children()) + triangles(n.children() + 1);
    }
    double work(std::uint32_t i) const {
        const detail::BihNode& n = tree.nodes[i];
        if (n.is_leaf()) return 0;
        return triangles(i) + work(n.children()) + work(n.children() + 1);
    }
    // {work, span} of the subtree at node i, with cuts as tasks or not.
    std::pair<double, double> span(std::uint32_t i, bool cuts_as_tasks) const {
        const detail::BihNode& n = tree.nodes[i];
        const double size = triangles(i);
        if (n.is_leaf()) return {0, 0};
        if (size < kParallelMin) return {work(i), work(i)};
        const auto l = n.children(), r = l + 1;
        const bool cut = triangles(l) == 0 || triangles(r) == 0;
        if (cut && !cuts_as_tasks) return {work(i), work(i)};
        const double own = size >= pass_min ? size / 2 : size;
        const auto a = span(l, cuts_as_tasks), b = span(r, cuts_as_tasks);
        return {size + a.first + b.first, own + std::max(a.second, b.second)};
    }
};

}  // namespace

int main(int argc, char** argv) {
    std::printf("| scene | triangles | work | span before | parallelism before | span with cuts as tasks | parallelism |\n");
    std::printf("|---|--:|--:|--:|--:|--:|--:|\n");
    for (int i = 1; i < argc; ++i) {
        const Scene scene = load_scene(argv[i]);
        detail::BihBuildParams p;
        p.split = detail::BihSplit::sah;
        p.threads = 1;
        const detail::BihTree tree = detail::build_bih(scene.triangles, p);
        const Walk walk{tree, static_cast<double>(p.parallel_pass_min)};
        const auto before = walk.span(0, false), after = walk.span(0, true);
        std::printf("| %s | %zu | %.0f | %.0f | %.2f | %.0f | %.2f |\n", argv[i], scene.triangles.size(), before.first,
                    before.second, before.first / before.second, after.second, after.first / after.second);
    }
}
