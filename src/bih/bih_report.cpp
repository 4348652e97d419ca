// The BIH build report: its shape and its SAH cost in the kd-tree's default cost units (15 per node
// visit, 20 per triangle test, whatever the build used), so that the two structures' reports compare.
#include <algorithm>
#include <cmath>

#include "bih_tree.hpp"

namespace cellrt::detail {
namespace {

constexpr double kReportTraversalCost = 15.0, kReportIntersectionCost = 20.0;

double area(const Box3& b) {
    if (b.is_empty()) return 0.0;
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return 2.0 * (x * y + y * z + z * x);
}

struct Totals {
    std::size_t inner = 0, leaves = 0, empty_leaves = 0, cuts = 0, triangles = 0, depth_sum = 0;
    int max_depth = 0;
    double cost = 0.0;
};

// Walks the hierarchy with each node's box (the parent's box cut by the node's clip plane).
void walk(const BihTree& tree, std::uint32_t index, const Box3& box, int depth, Totals& t) {
    const BihNode& n = tree.nodes[index];
    t.max_depth = std::max(t.max_depth, depth);
    if (n.is_leaf()) {
        ++t.leaves;
        t.triangles += n.count();
        if (n.count() == 0) ++t.empty_leaves;
        else t.depth_sum += static_cast<std::size_t>(depth);
        t.cost += kReportIntersectionCost * n.count() * area(box);
        return;
    }
    ++t.inner;
    const int a = n.axis();
    if (std::isinf(n.clip(0)) || std::isinf(n.clip(1))) ++t.cuts;
    t.cost += kReportTraversalCost * area(box);
    Box3 left = box, right = box;
    left.hi[a] = std::min(left.hi[a], n.clip(0));
    right.lo[a] = std::max(right.lo[a], n.clip(1));
    walk(tree, n.children(), left, depth + 1, t);
    walk(tree, n.children() + 1, right, depth + 1, t);
}


}  // namespace

TreeReport bih_report(const BihTree& tree, const BihBuildParams& params) {
    Totals t;
    walk(tree, 0, tree.bounds, 0, t);
    const std::size_t full = t.leaves - t.empty_leaves;
    const double root_area = area(tree.bounds);
    TreeReport r;
    r.nodes = t.inner + t.leaves;
    r.inner_nodes = t.inner;
    r.empty_space_nodes = t.cuts;
    r.leaves = t.leaves;
    r.empty_leaves = t.empty_leaves;
    r.depth_limit = params.max_depth;
    r.max_depth = t.max_depth;
    r.mean_leaf_depth = full ? double(t.depth_sum) / double(full) : 0.0;
    r.triangles_per_leaf = full ? double(t.triangles) / double(full) : 0.0;
    r.references_per_triangle = tree.triangles.empty() ? 0.0 : double(t.triangles) / double(tree.triangles.size());
    r.sah_cost = root_area > 0.0 ? t.cost / root_area : 0.0;
    return r;
}

}  // namespace cellrt::detail
