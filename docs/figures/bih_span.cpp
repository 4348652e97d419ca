// The parallelism a SAH BIH build's task tree allows on 16 threads, read off the finished tree: work
// and span in triangle passes (docs/BUILD_SPEED.md, "Sixteen threads: the BIH's task tree"). Each
// inner node of n triangles costs n (its decision: a binning pass and a partition pass over its
// range). Below 4,096 triangles (bih_build.cpp's kParallelMin) a subtree is one task: its span is
// its work. At a split of a larger node the two children are tasks. Three builders:
//  - "before" (bb00eca^): an empty-space cut (one child an empty leaf) kept its whole subtree in its
//    parent's task; nodes of 65,536 triangles or more were binned on all threads (span n / 2 + n / 32);
//  - "cuts" (bb00eca): the cut's occupied child is a task of its own;
//  - "blocks" (this change): also the partition on all threads; a node's passes run on all threads
//    from 16,384 triangles on (parallel_pass_min) when it holds more than the scene's triangles over
//    the threads (span n / 16), else on one.
// Work / span bounds the speed-up on 16 threads (and on any number).
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
    // {work, span} of the subtree at node i; `blocks`: the smallest node whose passes are all parallel
    // (0: only the binning of nodes from 65,536 on, the builders before).
    std::pair<double, double> span(std::uint32_t i, bool cuts_as_tasks, double blocks) const {
        const detail::BihNode& n = tree.nodes[i];
        const double size = triangles(i);
        if (n.is_leaf()) return {0, 0};
        if (size < kParallelMin) return {work(i), work(i)};
        const auto l = n.children(), r = l + 1;
        const bool cut = triangles(l) == 0 || triangles(r) == 0;
        if (cut && !cuts_as_tasks) return {work(i), work(i)};
        const double own = blocks > 0 ? (size >= blocks ? size / 16 : size) : (size >= 65536 ? size / 2 + size / 32 : size);
        const auto a = span(l, cuts_as_tasks, blocks), b = span(r, cuts_as_tasks, blocks);
        return {size + a.first + b.first, own + std::max(a.second, b.second)};
    }
};

}  // namespace

int main(int argc, char** argv) {
    std::printf("| scene | triangles | work | before | cuts | blocks |\n");
    std::printf("|---|--:|--:|--:|--:|--:|\n");
    for (int i = 1; i < argc; ++i) {
        const Scene scene = load_scene(argv[i]);
        detail::BihBuildParams p;
        p.split = detail::BihSplit::sah;
        p.threads = 1;
        const detail::BihTree tree = detail::build_bih(scene.triangles, p);
        const Walk walk{tree};
        const double work = walk.work(0);
        std::printf("| %s | %zu | %.0f", argv[i], scene.triangles.size(), work);
        const double blocks = std::max(16384.0, static_cast<double>(scene.triangles.size() / 16 + 1));
        const std::pair<bool, double> builders[] = {{false, 0}, {true, 0}, {true, blocks}};
        for (const auto& [cuts, blocks] : builders) std::printf(" | %.2f", work / walk.span(0, cuts, blocks).second);
        std::printf(" |\n");
    }
}
