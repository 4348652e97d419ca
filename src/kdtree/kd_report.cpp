// The kd-tree build report (Mitsuba prints the same figures after a build): shape of the tree, how
// often triangles are referenced, and the tree's SAH cost, the expected cost of a random ray that
// hits the root cell, in the builder's cost units.
#include <algorithm>

#include "kd_tree.hpp"

namespace cellrt::detail {
namespace {

struct Totals {
    std::size_t inner = 0, leaves = 0, empty_leaves = 0, references = 0;
    std::size_t depth_sum = 0;  // over non-empty leaves
    int max_depth = 0;
    double cost = 0.0;          // sum of cost x cell area
};

double area(const Box3& b) {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return 2.0 * (x * y + y * z + z * x);
}

void walk(const KdTree& tree, const KdBuildParams& p, std::uint32_t index, const Box3& cell, int depth, Totals& t) {
    const KdNode& n = tree.nodes[index];
    t.max_depth = std::max(t.max_depth, depth);
    if (n.is_leaf()) {
        ++t.leaves;
        t.references += n.count();
        if (n.count() == 0) ++t.empty_leaves;
        else t.depth_sum += static_cast<std::size_t>(depth);
        t.cost += p.intersection_cost * n.count() * area(cell);
        return;
    }
    ++t.inner;
    t.cost += p.traversal_cost * area(cell);
    Box3 left = cell, right = cell;
    left.hi[n.axis()] = n.split();
    right.lo[n.axis()] = n.split();
    walk(tree, p, n.children(), left, depth + 1, t);
    walk(tree, p, n.children() + 1, right, depth + 1, t);
}

}  // namespace

TreeReport kd_report(const KdTree& tree, const KdBuildParams& p) {
    Totals t;
    walk(tree, p, 0, tree.bounds, 0, t);
    const std::size_t full = t.leaves - t.empty_leaves;
    const double root_area = area(tree.bounds);
    TreeReport r;
    r.nodes = t.inner + t.leaves;
    r.inner_nodes = t.inner;
    r.leaves = t.leaves;
    r.empty_leaves = t.empty_leaves;
    r.depth_limit = p.depth_limit(tree.triangle_count);
    r.max_depth = t.max_depth;
    r.mean_leaf_depth = full ? double(t.depth_sum) / double(full) : 0.0;
    r.triangles_per_leaf = full ? double(t.references) / double(full) : 0.0;
    r.references_per_triangle = tree.triangle_count ? double(t.references) / double(tree.triangle_count) : 0.0;
    r.sah_cost = root_area > 0.0 ? t.cost / root_area : 0.0;
    return r;
}

}  // namespace cellrt::detail
