// The SAH kd-tree: build parameters, the built tree and its report.
//
// Build (kd_build.cpp): the surface area heuristic with min-max binning near the root (Shevtsov,
// Soupikov, Kapustin, "Highly Parallel Fast KD-tree Construction for Interactive Ray Tracing of
// Dynamic Scenes", 2007) and the exact O(N log N) event sweep below (Wald & Havran, "On building fast
// kd-Trees for Ray Tracing, and on doing that in O(N log N)", 2006), with perfect splits.
// Traversals (kd_traversal.hpp): Havran's TA_rec, the classic stack traversal and the study's
// branchless variant.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cellrt/box.hpp"
#include "cellrt/triangle.hpp"
#include "kd_node.hpp"

namespace cellrt::detail {

// Hard bound on the depth of any kd-tree; traversal stacks are sized by it.
inline constexpr int kKdMaxDepth = 60;

enum class KdBuildMethod { hybrid, sweep, binned };

// The traversal cost a tree for SIMD packets is built with by default: a packet tests a triangle on
// all its lanes for about the price of one node step (its stack entries are whole lane vectors), so
// a step weighs three times the single-ray constant. Measured: docs/BENCHMARKS.md.
inline constexpr double kKdPacketTraversalCost = 45.0;

// Build parameters. Names are those of `-P NAME=VALUE`; defaults and ranges are documented in
// docs/KDTREE.md and validated by KdStructure::param_table() (kd_structure.cpp).
struct KdBuildParams {
    // Cost of one traversal step and of one triangle test (Wald & Havran's constants). Trees for
    // SIMD packets default to kKdPacketTraversalCost instead (read_kd_params).
    double traversal_cost = 15.0;
    double intersection_cost = 20.0;
    // A split with an empty side costs (1 - empty_bonus) times its SAH value (Mitsuba: 0.1; Wald &
    // Havran's lambda = 0.8 is empty_bonus = 0.2).
    double empty_bonus = 0.1;
    // Depth limit; 0 chooses 8 + 1.3 log2 N, capped at kKdMaxDepth.
    int max_depth = 0;
    // A node with at most this many triangles is always a leaf (Mitsuba's stopPrims).
    int leaf_size = 6;
    KdBuildMethod method = KdBuildMethod::hybrid;
    // Hybrid: nodes with more references than this are split by min-max binning, the rest by the sweep.
    int sweep_below = 4096;
    int bins = 128;
    // Clip straddling triangles to each child cell, so that child boxes are tight.
    bool perfect_splits = true;
    // With perfect splits, a straddler is clipped only if its box spans at least this fraction of
    // the cell on an axis other than the split axis; otherwise its box is cut to each child cell.
    // 0 clips every straddler (the exact perfect splits of Wald & Havran). Measured: BUILD_SPEED.md.
    double clip_ratio = 0.05;
    // Replace a built subtree that is no cheaper (by the SAH) than a single leaf by that leaf.
    bool retract = true;
    // Bad-refinement rule: splits that cost more than a leaf are allowed this many times on a path
    // (Mitsuba: 3; 0 builds 2 to 5% fewer nodes for an SAH cost within 0.2%: BUILD_SPEED.md).
    int max_bad_refines = 0;
    // Build threads; 0: all hardware threads. The tree is the same for every value.
    unsigned threads = 0;
    // In parallel builds, nodes with at least this many references are also binned and partitioned by
    // several threads (not a `-P` parameter: tests lower it to check that the tree stays the same).
    std::size_t parallel_pass_min = 65536;

    int depth_limit(std::size_t triangles) const;
};

struct KdTree {
    // nodes[0] is the root and nodes[1] padding, so that child pairs start at even indices.
    std::vector<KdNode> nodes;
    std::vector<std::uint32_t> indices;  // leaf triangle lists, ascending within a leaf
    Box3 bounds;                         // the root cell: the scene's bounding box
    std::size_t triangle_count = 0;
};

KdTree build_kdtree(std::span<const Triangle> triangles, const KdBuildParams& params);

}  // namespace cellrt::detail
