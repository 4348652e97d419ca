// The wide BVH's builder: a binary BVH by the surface area heuristic over binned centroids (Wald,
// "On fast Construction of SAH-based Bounding Volume Hierarchies", RT 2007), with spatial splits
// where large triangles overlap (Stich, Friedrich, Dietrich, "Spatial Splits in Bounding Volume
// Hierarchies", HPG 2009), collapsed into nodes of eight children by pulling up the largest child
// until a node is full (Wald, Benthin, Boulos 2008, section 3). Without spatial splits each triangle
// lies in exactly one leaf and every box is the exact bounds of what lies below it; with them a
// triangle cut by a plane lies in a leaf on each side, each box holding its part, so a conservative
// box test (kernel/traversal.hpp's margin) never misses a hit either way.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "bvh/bvh_node.hpp"
#include "cellrt/box.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt::detail {

struct BvhBuildOptions {
    int bins = 16;                   // centroid bins per axis
    int max_leaf = 8;                // triangles per leaf, 1..8 (a leaf is one 8-lane group)
    double traversal_cost = 1.0;     // of visiting a node (eight box tests)
    double intersection_cost = 2.0;  // of testing a leaf (up to eight triangles at once)
    double split_budget = 0.5;       // spatial splits: about this many extra references per triangle
    unsigned threads = 0;            // build threads; 0: all hardware threads. The tree is the same for every value.
    // In parallel builds, the children of nodes with at least this many references are built as
    // tasks (not a `-P` parameter: tests lower it to check that the tree stays the same).
    std::size_t parallel_min = 4096;
};

struct BvhTree {
    std::vector<BvhNode> nodes;  // the root is node 0; empty for a scene without triangles
    std::vector<BvhLeaf> leaves;
    Box3 bounds;
    int depth = 0;               // of the deepest wide node, the root's being 0
    std::size_t binary_nodes = 0;
    double sah_cost = 0.0;       // of the binary tree, in the options' cost units
    std::size_t references = 0;  // triangles in leaves, a triangle cut by spatial splits once per leaf
    double mean_leaf_triangles = 0.0;
    double mean_leaf_depth = 0.0;  // a leaf's depth is its wide parent's plus one
};

BvhTree build_bvh(std::span<const Triangle> triangles, const BvhBuildOptions& options);

}  // namespace cellrt::detail
