// The build report of any tree (Mitsuba prints the same figures after a build): its shape, how often
// triangles are referenced, and its SAH cost, the expected cost of a random ray that meets the root
// cell (the sum over nodes of cost x cell area, over the root's area; MacDonald & Booth 1990). A
// child's cell is its parent's cut at the child's plane, as the traversals see it (Traits::plane).
#pragma once

#include <algorithm>
#include <cmath>

#include "cellrt/accelerator.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {

struct ReportCosts {
    double traversal, intersection;  // of a node visit and of a triangle test
};

template <class Traits>
class TreeReporter {
public:
    TreeReporter(const TreeView<Traits>& tree, ReportCosts costs) : tree_(tree), costs_(costs) {}

    TreeReport report(int depth_limit, std::size_t triangle_count) {
        walk(0, tree_.bounds, 0);
        const std::size_t full = leaves_ - empty_leaves_;
        const double root_area = area(tree_.bounds);
        TreeReport r;
        r.nodes = inner_ + leaves_;
        r.inner_nodes = inner_;
        if (Traits::kGaps) r.empty_space_nodes = cuts_;
        r.leaves = leaves_;
        r.empty_leaves = empty_leaves_;
        r.depth_limit = depth_limit;
        r.max_depth = max_depth_;
        r.mean_leaf_depth = full ? double(depth_sum_) / double(full) : 0.0;
        r.triangles_per_leaf = full ? double(references_) / double(full) : 0.0;
        r.references_per_triangle = triangle_count ? double(references_) / double(triangle_count) : 0.0;
        r.sah_cost = root_area > 0.0 ? cost_ / root_area : 0.0;
        return r;
    }

private:
    // With gaps a child's cell can be empty (a plane at infinity cuts off empty space): area 0.
    static double area(const Box3& b) {
        if (Traits::kGaps && b.is_empty()) return 0.0;
        const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
        return 2.0 * (x * y + y * z + z * x);
    }

    void walk(std::uint32_t index, const Box3& cell, int depth) {
        const typename Traits::Node& n = tree_.nodes[index];
        max_depth_ = std::max(max_depth_, depth);
        if (n.is_leaf()) {
            ++leaves_;
            references_ += n.count();
            if (n.count() == 0) ++empty_leaves_;
            else depth_sum_ += static_cast<std::size_t>(depth);
            cost_ += costs_.intersection * n.count() * area(cell);
            return;
        }
        ++inner_;
        const int a = n.axis();
        const float left_plane = Traits::plane(n, 0), right_plane = Traits::plane(n, 1);
        if (std::isinf(left_plane) || std::isinf(right_plane)) ++cuts_;
        cost_ += costs_.traversal * area(cell);
        Box3 left = cell, right = cell;
        // One plane lies inside its cell; two clip planes may lie beyond it.
        left.hi[a] = Traits::kGaps ? std::min(left.hi[a], left_plane) : left_plane;
        right.lo[a] = Traits::kGaps ? std::max(right.lo[a], right_plane) : right_plane;
        walk(n.children(), left, depth + 1);
        walk(n.children() + 1, right, depth + 1);
    }

    const TreeView<Traits>& tree_;
    ReportCosts costs_;
    std::size_t inner_ = 0, leaves_ = 0, empty_leaves_ = 0, cuts_ = 0, references_ = 0;
    std::size_t depth_sum_ = 0;  // over non-empty leaves
    int max_depth_ = 0;
    double cost_ = 0.0;  // sum of cost x cell area
};

template <class Traits>
TreeReport tree_report(const TreeView<Traits>& tree, ReportCosts costs, int depth_limit, std::size_t triangle_count) {
    return TreeReporter<Traits>(tree, costs).report(depth_limit, triangle_count);
}

}  // namespace cellrt::detail
