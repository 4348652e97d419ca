// The Bounding Interval Hierarchy (Wächter & Keller, "Instant Ray Tracing: The Bounding Interval
// Hierarchy", EGSR 2006): build parameters, the built hierarchy and its report. Build in
// bih_build.cpp, traversals in bih_traversal.hpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bih_node.hpp"
#include "cellrt/box.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt::detail {

// Hard bound on the depth of any BIH; traversal stacks are sized by it.
inline constexpr int kBihMaxDepth = 64;

// Build parameters (`-P NAME=VALUE`; docs/BIH.md).
// How a node's split plane is chosen: the study's global heuristic (Wächter & Keller section 2.2),
// or the surface area heuristic over binned centres (MacDonald & Booth 1990; binning after Wald
// 2007), each candidate costed with the cells a BIH gives its children: the node's cell cut by one
// clip plane on the split axis.
enum class BihSplit { global, sah };

struct BihBuildParams {
    BihSplit split = BihSplit::global;
    // A node with at most this many triangles is a leaf.
    int leaf_size = 2;
    int max_depth = kBihMaxDepth;
    // When all triangles fall on one side of the candidate plane, an empty-space node (one child
    // empty, its plane at infinity) is emitted if more than this fraction of the node's width on the
    // axis is empty (Wächter & Keller section 2.2; Sunflow's 1/1.3 rule is 0.23). 1 disables it.
    double empty_cut = 0.23;
    // split=sah only: the SAH's cost of a node visit and of a triangle test (by default the kd-tree's,
    // so that the two structures' trees compare), and the largest leaf it makes when no split is cheaper.
    double traversal_cost = 15.0;
    double intersection_cost = 20.0;
    int sah_max_leaf = 16;
    unsigned threads = 0;  // 0: all hardware threads; the hierarchy is the same for every value
    // Parallel builds: nodes with at least this many triangles, and more than the scene's triangles
    // over the threads, are partitioned (and with split=sah binned) by several threads: the nodes near
    // the root, which would otherwise hold the others up (not a `-P` parameter: a test lowers it to
    // check that the hierarchy stays the same).
    std::size_t parallel_pass_min = 16384;
};

struct BihTree {
    // nodes[0] is the root and nodes[1] an empty leaf (padding, so that pairs start at even indices).
    std::vector<BihNode> nodes;
    std::vector<Triangle> triangles;    // the scene's triangles, reordered so that leaves are ranges
    std::vector<std::uint32_t> prims;   // prims[i]: the scene index of triangles[i]
    Box3 bounds;
};

BihTree build_bih(std::span<const Triangle> triangles, const BihBuildParams& params);

}  // namespace cellrt::detail
