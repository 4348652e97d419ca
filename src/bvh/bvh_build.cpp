#include "bvh/bvh_build.hpp"

#include <algorithm>
#include <array>

#include "cellrt/ray.hpp"

namespace cellrt::detail {
namespace {

// Beyond this depth the binary build splits at the object median, so that a pathological scene (one
// triangle cut off per level) cannot recurse once per triangle.
constexpr int kSahDepth = 64;

double area(const Box3& b) { return b.is_empty() ? 0.0 : static_cast<double>(b.area()); }

struct BinaryNode {
    Box3 box;
    std::uint32_t left = 0, right = 0;  // inner
    std::uint32_t first = 0, count = 0;  // leaf: its triangles in `order`
    bool leaf = false;
};

class BinaryBuilder {
public:
    BinaryBuilder(std::span<const Triangle> triangles, const BvhBuildOptions& o) : tris_(triangles), o_(o) {
        boxes_.reserve(tris_.size());
        centroids_.reserve(tris_.size());
        order_.resize(tris_.size());
        for (std::size_t i = 0; i < tris_.size(); ++i) {
            boxes_.push_back(tris_[i].bounds());
            centroids_.push_back(boxes_.back().center());
            order_[i] = static_cast<std::uint32_t>(i);
        }
        nodes_.reserve(2 * tris_.size());
    }

    void build() { build(0, static_cast<std::uint32_t>(tris_.size()), 0); }

    const std::vector<BinaryNode>& nodes() const { return nodes_; }
    const std::vector<std::uint32_t>& order() const { return order_; }
    double cost() const { return cost_; }

private:
    // Leaf tests, in groups of eight lanes.
    double leaf_cost(std::uint32_t n) const { return o_.intersection_cost * double((n + kBvhWidth - 1) / kBvhWidth); }

    struct Split {
        int axis = -1;
        int bin = 0;  // centroids in bins [0, bin) go left
        double cost = 0.0;
    };

    // Clamped as a float, before the conversion: a centroid at the box's far side gives `bins`, and
    // where the extent is subnormal, bins / extent is inf and k inf or NaN, which no int holds.
    int bin_of(const Vec3& c, int axis, const Box3& cbox) const {
        const float extent = cbox.hi[axis] - cbox.lo[axis];
        const float k = (c[axis] - cbox.lo[axis]) * (static_cast<float>(o_.bins) / extent);
        return k > 0.f ? static_cast<int>(std::min(k, static_cast<float>(o_.bins - 1))) : 0;
    }

    // The cheapest binned SAH split of the node's triangles, or axis -1 when all centroids coincide.
    Split best_split(std::uint32_t first, std::uint32_t count, const Box3& box, const Box3& cbox) const {
        Split best;
        const double parent = area(box);
        std::array<Box3, 256> bin_box;
        std::array<std::uint32_t, 256> bin_count;
        std::array<double, 256> right_area;
        std::array<std::uint32_t, 256> right_count;
        for (int a = 0; a < 3; ++a) {
            if (!(cbox.hi[a] > cbox.lo[a])) continue;
            std::fill_n(bin_box.begin(), o_.bins, Box3{});
            std::fill_n(bin_count.begin(), o_.bins, 0u);
            for (std::uint32_t i = first; i < first + count; ++i) {
                const int k = bin_of(centroids_[order_[i]], a, cbox);
                bin_box[k].extend(boxes_[order_[i]]);
                ++bin_count[k];
            }
            Box3 acc;
            std::uint32_t n = 0;
            for (int k = o_.bins - 1; k > 0; --k) {  // right side of a split before bin k
                acc.extend(bin_box[k]);
                n += bin_count[k];
                right_area[k] = area(acc);
                right_count[k] = n;
            }
            acc = Box3{};
            n = 0;
            for (int k = 1; k < o_.bins; ++k) {
                acc.extend(bin_box[k - 1]);
                n += bin_count[k - 1];
                if (n == 0 || right_count[k] == 0) continue;
                const double c = o_.traversal_cost +
                                 (area(acc) * leaf_cost(n) + right_area[k] * leaf_cost(right_count[k])) / parent;
                if (best.axis < 0 || c < best.cost) best = {a, k, c};
            }
        }
        return best;
    }

    std::uint32_t build(std::uint32_t first, std::uint32_t count, int depth) {
        Box3 box, cbox;
        for (std::uint32_t i = first; i < first + count; ++i) {
            box.extend(boxes_[order_[i]]);
            cbox.extend(centroids_[order_[i]]);
        }
        const auto index = static_cast<std::uint32_t>(nodes_.size());
        nodes_.push_back({});
        nodes_[index].box = box;
        const double a = area(box);
        Split split;
        if (count > 1 && depth < kSahDepth) split = best_split(first, count, box, cbox);
        const bool fits = count <= static_cast<std::uint32_t>(o_.max_leaf);
        if (count <= 1 || (fits && (split.axis < 0 || leaf_cost(count) <= split.cost))) {
            nodes_[index].leaf = true;
            nodes_[index].first = first;
            nodes_[index].count = count;
            cost_ += leaf_cost(count) * a;
            return index;
        }
        std::uint32_t left_count = count / 2;  // the object median, where no SAH split applies
        if (split.axis >= 0) {
            const auto mid = std::partition(order_.begin() + first, order_.begin() + first + count, [&](std::uint32_t t) {
                return bin_of(centroids_[t], split.axis, cbox) < split.bin;
            });
            left_count = static_cast<std::uint32_t>(mid - (order_.begin() + first));
        }
        cost_ += o_.traversal_cost * a;
        const std::uint32_t left = build(first, left_count, depth + 1);
        const std::uint32_t right = build(first + left_count, count - left_count, depth + 1);
        nodes_[index].left = left;
        nodes_[index].right = right;
        return index;
    }

    std::span<const Triangle> tris_;
    BvhBuildOptions o_;
    std::vector<Box3> boxes_;
    std::vector<Vec3> centroids_;
    std::vector<std::uint32_t> order_;
    std::vector<BinaryNode> nodes_;
    double cost_ = 0.0;  // sum of cost x area
};

// Collapses the binary tree into wide nodes: a node's children start as a binary node's two, and the
// inner child of largest area is replaced by its own two until there are eight or only leaves.
class Collapser {
public:
    Collapser(std::span<const Triangle> tris, const BinaryBuilder& b, BvhTree& out) : tris_(tris), b_(b), out_(out) {}

    std::uint32_t emit(std::uint32_t binary, int depth) {
        const std::vector<BinaryNode>& bn = b_.nodes();
        std::array<std::uint32_t, kBvhWidth> kids{};
        int n = 0;
        if (bn[binary].leaf) {
            kids[n++] = binary;
        } else {
            kids[n++] = bn[binary].left;
            kids[n++] = bn[binary].right;
        }
        while (n < kBvhWidth) {
            int widest = -1;
            for (int k = 0; k < n; ++k)
                if (!bn[kids[k]].leaf && (widest < 0 || area(bn[kids[k]].box) > area(bn[kids[widest]].box))) widest = k;
            if (widest < 0) break;
            const BinaryNode& w = bn[kids[widest]];
            kids[widest] = w.left;
            kids[n++] = w.right;
        }
        out_.depth = std::max(out_.depth, depth);
        const auto index = static_cast<std::uint32_t>(out_.nodes.size());
        out_.nodes.emplace_back();
        init_empty(out_.nodes[index]);
        for (int k = 0; k < n; ++k) {
            const BinaryNode& c = bn[kids[k]];
            for (int a = 0; a < 3; ++a) {
                out_.nodes[index].lo[a][k] = c.box.lo[a];
                out_.nodes[index].hi[a][k] = c.box.hi[a];
            }
            const std::uint32_t word = c.leaf ? leaf(c, depth + 1) : emit(kids[k], depth + 1);
            out_.nodes[index].child[k] = word;
        }
        return index;
    }

private:
    static void init_empty(BvhNode& node) {
        for (int k = 0; k < kBvhWidth; ++k) {
            for (int a = 0; a < 3; ++a) {
                node.lo[a][k] = kInfinity;
                node.hi[a][k] = -kInfinity;
            }
            node.child[k] = BvhNode::kEmptyChild;
        }
    }

    std::uint32_t leaf(const BinaryNode& c, int depth) {
        leaf_depths_ += static_cast<std::size_t>(depth);
        BvhLeaf l{};
        for (std::uint32_t lane = 0; lane < kBvhWidth; ++lane) {
            l.prim[lane] = kNoHit;
            if (lane >= c.count) continue;
            const std::uint32_t prim = b_.order()[c.first + lane];
            const Triangle& t = tris_[prim];
            for (int a = 0; a < 3; ++a) {
                l.v[0][a][lane] = t.v0[a];
                l.v[1][a][lane] = t.v1[a];
                l.v[2][a][lane] = t.v2[a];
            }
            l.prim[lane] = prim;
        }
        out_.leaves.push_back(l);
        return BvhNode::leaf_word(static_cast<std::uint32_t>(out_.leaves.size() - 1), c.count);
    }

public:
    std::size_t leaf_depths() const { return leaf_depths_; }

private:
    std::span<const Triangle> tris_;
    const BinaryBuilder& b_;
    BvhTree& out_;
    std::size_t leaf_depths_ = 0;
};

}  // namespace

BvhTree build_bvh(std::span<const Triangle> triangles, const BvhBuildOptions& options) {
    BvhTree tree;
    if (triangles.empty()) return tree;
    BinaryBuilder builder(triangles, options);
    builder.build();
    tree.bounds = builder.nodes()[0].box;
    tree.binary_nodes = builder.nodes().size();
    const double root = area(tree.bounds);
    tree.sah_cost = root > 0.0 ? builder.cost() / root : 0.0;
    Collapser collapser(triangles, builder, tree);
    collapser.emit(0, 0);
    tree.mean_leaf_triangles = double(triangles.size()) / double(tree.leaves.size());
    tree.mean_leaf_depth = double(collapser.leaf_depths()) / double(tree.leaves.size());
    return tree;
}

}  // namespace cellrt::detail
