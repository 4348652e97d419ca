#include "bvh/bvh_build.hpp"
#include "bvh/split_reference.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include <tbb/task_group.h>

#include "cellrt/error.hpp"
#include "cellrt/ray.hpp"
#include "kernel/binning.hpp"
#include "kernel/box_lanes.hpp"
#include "kernel/subtree.hpp"

namespace cellrt::detail {
namespace {

// Beyond this depth the binary build splits at the object median, so that a pathological scene (one
// triangle cut off per level) cannot recurse once per triangle.
constexpr int kSahDepth = 64;
// A child word holds a leaf's index in 28 bits (bvh_node.hpp).
constexpr std::size_t kMaxLeaves = std::size_t{1} << 28;

double area(const Box3& b) { return b.is_empty() ? 0.0 : static_cast<double>(b.area()); }

// Spatial splits are searched only where the object split's two boxes overlap by more than this
// share of the root's area (Stich, Friedrich, Dietrich, "Spatial Splits in Bounding Volume
// Hierarchies", HPG 2009, section 4.4: their alpha, whose value 10^-5 they recommend).
constexpr double kSplitOverlap = 1e-5;
// Nor in nodes of fewer references: there they change the SAH cost of the shared scenes' trees by
// under 0.1% (docs/BVH.md), and such nodes are a third of the search's work.
constexpr std::size_t kSpatialMin = 32;
// Nor where no reference spans at least this share of the node's box on some axis: a plane then
// cuts only references small against the children, which an object split separates almost as well.
// On a finely tessellated mesh (the bunny) that skips four fifths of the search's work for 0.35% of
// SAH cost, and leaves the trees of Sponza, Sibenik and the city unchanged, byte for byte (a
// measured rule, not the paper's: docs/BVH.md).
constexpr float kSpatialReach = 0.25f;

// A reference: a triangle, or the part of it in a region cut by spatial splits, with the bounds of
// that part (conservative: it contains every point of the triangle in the region).
struct Ref {
    Box3 box;
    std::uint32_t prim;
};

struct BinaryNode {
    Box3 box;
    std::uint32_t left = 0, right = 0;  // inner
    std::uint32_t first = 0, count = 0;  // leaf: its triangles in `order`
    bool leaf = false;
};

// A box in lanes, extended as Box3::extend extends (minps and maxps in its operand order: an equal
// value keeps the bound) and measured with Box3::area's arithmetic, so the same bits. No member
// initializers: arrays of them are filled as far as they are used.
struct LaneBox {
    F4 lo, hi;

    static LaneBox empty() { return {F4{} + kInfinity, F4{} - kInfinity}; }
    void extend(const LaneBox& b) {
        lo = b.lo < lo ? b.lo : lo;
        hi = hi < b.hi ? b.hi : hi;
    }
    F4 centre() const { return (lo + hi) * 0.5f; }  // Box3::center's arithmetic
    Box3 box() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
    double area() const {
        if (lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]) return 0.0;
        const F4 e = hi - lo;
        return static_cast<double>(2.f * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]));
    }
};

// Per axis and bin, how many references a binning put there and the bounds of their boxes, for
// binning passes that place each reference on the three axes at once (kernel/box_lanes.hpp).
struct LaneBoxBins {
    std::array<std::array<LaneBox, 256>, 3> box;
    std::array<std::array<std::uint32_t, 256>, 3> count;

    explicit LaneBoxBins(int bins) {
        for (int a = 0; a < 3; ++a) {
            std::fill_n(box[a].begin(), bins, LaneBox::empty());
            std::fill_n(count[a].begin(), bins, 0u);
        }
    }
    void add(int a, int k, const LaneBox& b) {
        box[a][k].extend(b);
        ++count[a][k];
    }
};

// The bins of `box` on each axis as AxisBins makes them (`bins` over the extent, or one bin where
// there is none): origins, scales and the last bin, one lane per axis.
struct LaneAxes {
    F4 origin{}, scale{}, last{};
    LaneAxes(const Box3& box, int bins) : last(F4{} + static_cast<float>(bins - 1)) {
        for (int a = 0; a < 3; ++a) {
            const AxisBins axis(box.lo[a], box.hi[a], bins);
            origin[a] = axis.lo;
            scale[a] = axis.scale;
        }
    }
    I4 bins_of(F4 x) const { return lane_bins_guarded(x, origin, scale, last); }
};

// Whether some reference spans kSpatialReach of `box` on an axis along which the box has an extent.
// (It stops at the first: where splits pay, one comes early.)
bool any_reaches_across(std::span<const Ref> refs, const Box3& box) {
    Vec3 reach;
    for (int a = 0; a < 3; ++a) {
        const float extent = box.hi[a] - box.lo[a];
        reach[a] = extent > 0.f ? kSpatialReach * extent : std::numeric_limits<float>::infinity();
    }
    for (const Ref& r : refs) {
        const Vec3 width = r.box.hi - r.box.lo;
        if (width.x >= reach.x || width.y >= reach.y || width.z >= reach.z) return true;
    }
    return false;
}

// The binary tree by the binned SAH over reference centroids (Wald 2007), with spatial splits
// (Stich et al. 2009) where they pay and the budget of extra references allows.
class BinaryBuilder {
public:
    BinaryBuilder(std::span<const Triangle> triangles, const BvhBuildOptions& o) : tris_(triangles), o_(o) {
        tree_.nodes.reserve(2 * tris_.size());
        tree_.order.reserve(tris_.size());
    }

    void build() {
        std::vector<Ref> refs(tris_.size());
        Box3 root;
        for (std::size_t i = 0; i < tris_.size(); ++i) {
            refs[i] = {tris_[i].bounds(), static_cast<std::uint32_t>(i)};
            root.extend(refs[i].box);
        }
        root_area_ = area(root);
        auto run = [&] { build(tree_, std::move(refs), 0, o_.split_budget * static_cast<double>(tris_.size())); };
        run_build(o_.threads, run);
        // Summed in the nodes' order, which is the depth-first order of the sequential recursion:
        // the same bits at any thread count.
        for (const BinaryNode& n : tree_.nodes)
            cost_ += (n.leaf ? leaf_cost(n.count) : o_.traversal_cost) * area(n.box);
    }

    const std::vector<BinaryNode>& nodes() const { return tree_.nodes; }
    const std::vector<std::uint32_t>& order() const { return tree_.order; }
    double cost() const { return cost_; }

private:
    // Leaf tests, in groups of eight lanes.
    double leaf_cost(std::size_t n) const { return o_.intersection_cost * double((n + kBvhWidth - 1) / kBvhWidth); }
    double split_cost(double left_area, std::size_t nl, double right_area, std::size_t nr, double parent) const {
        return o_.traversal_cost + (left_area * leaf_cost(nl) + right_area * leaf_cost(nr)) / parent;
    }

    struct Split {
        int axis = -1;
        int bin = 0;  // object split: centroids in bins [0, bin) go left; spatial: the plane before bin `bin`
        double cost = 0.0;
        bool spatial = false;
        float pos = 0.f;              // spatial: the plane
        Box3 left_box, right_box;     // object split: the children's boxes
    };

    // The cheapest binned SAH split of the references by centroid, or axis -1 when all centroids coincide.
    Split object_split(std::span<const Ref> refs, double parent, const Box3& cbox) const {
        Split best;
        const int bins = o_.bins;
        // One pass bins the three axes, each centre's three bins computed at once.
        const LaneAxes axes(cbox, bins);
        LaneBoxBins binned(bins);
        for (const Ref& r : refs) {
            const LaneBox b{lanes_lo(r), lanes_hi(r)};
            const I4 k = axes.bins_of(b.centre());
            for (int a = 0; a < 3; ++a) binned.add(a, k[a], b);
        }
        std::array<LaneBox, 256> right_box;
        std::array<std::uint32_t, 256> right_count;
        for (int a = 0; a < 3; ++a) {
            if (!(cbox.hi[a] > cbox.lo[a])) continue;
            LaneBox acc = LaneBox::empty();
            std::uint32_t n = 0;
            for (int k = bins - 1; k > 0; --k) {  // right side of a split before bin k
                acc.extend(binned.box[a][k]);
                n += binned.count[a][k];
                right_box[k] = acc;
                right_count[k] = n;
            }
            acc = LaneBox::empty();
            n = 0;
            for (int k = 1; k < bins; ++k) {
                // After an empty bin the candidate is the one before it, box for box (extending by an
                // empty box changes no bit), so its cost is no less: a small node's many empty bins
                // are passed over without their areas.
                if (binned.count[a][k - 1] == 0) continue;
                acc.extend(binned.box[a][k - 1]);
                n += binned.count[a][k - 1];
                if (right_count[k] == 0) continue;
                const double c = split_cost(acc.area(), n, right_box[k].area(), right_count[k], parent);
                if (best.axis < 0 || c < best.cost) best = {a, k, c, false, 0.f, acc.box(), right_box[k].box()};
            }
        }
        return best;
    }

    // Stich et al. section 4.2: bins of equal width over the node's box; a reference is counted in
    // the bin where it enters and in the one where it leaves. Where Stich et al. clip it into every
    // bin it crosses, its box is cut to the planes instead: the union of the cut boxes left of a
    // plane is the union of the boxes entering before it, cut at the plane, so one box per bin
    // and side is enough (on Sponza the SAH cost of the tree is within 0.1% of clipping's, for a
    // quarter of the search's instructions). The children's boxes come from the clipped parts
    // (split_reference).
    // The cheapest plane between bins whose extra references fit in `budget`; axis -1 when none does.
    Split spatial_split(std::span<const Ref> refs, double parent, const Box3& box, double budget) const {
        Split best;
        const int bins = o_.bins;
        // One pass bins the three axes: each reference's entry and exit bins on all three at once.
        const LaneAxes axes(box, bins);
        LaneBoxBins entry(bins), exit(bins);
        for (const Ref& r : refs) {
            const LaneBox b{lanes_lo(r), lanes_hi(r)};
            const I4 first = axes.bins_of(b.lo), to = axes.bins_of(b.hi);
            const I4 last = to < first ? first : to;
            for (int a = 0; a < 3; ++a) {
                entry.add(a, first[a], b);
                exit.add(a, last[a], b);
            }
        }
        std::array<LaneBox, 256> right_box;
        std::array<std::uint32_t, 256> right_count;
        for (int a = 0; a < 3; ++a) {
            if (!(box.hi[a] > box.lo[a])) continue;
            const float width = (box.hi[a] - box.lo[a]) / static_cast<float>(bins);
            const auto plane = [&](int k) { return box.lo[a] + width * static_cast<float>(k); };
            LaneBox acc = LaneBox::empty();
            std::uint32_t n = 0;
            for (int k = bins - 1; k > 0; --k) {  // right of the plane before bin k
                acc.extend(exit.box[a][k]);
                n += exit.count[a][k];
                right_box[k] = acc;
                right_box[k].lo[a] = std::max(acc.lo[a], plane(k));
                right_count[k] = n;
            }
            acc = LaneBox::empty();
            n = 0;
            for (int k = 1; k < bins; ++k) {
                acc.extend(entry.box[a][k - 1]);
                n += entry.count[a][k - 1];
                if (n == 0 || right_count[k] == 0) continue;
                if (static_cast<double>(n + right_count[k] - refs.size()) > budget) continue;
                LaneBox left = acc;
                left.hi[a] = std::min(acc.hi[a], plane(k));
                const double c = split_cost(left.area(), n, right_box[k].area(), right_count[k], parent);
                if (best.axis < 0 || c < best.cost) best = {a, k, c, true, plane(k), {}, {}};
            }
        }
        return best;
    }

    // Cuts `refs` at the spatial split `s`: references on one side go there, a straddler's parts
    // to both sides they reach.
    void partition_spatial(std::vector<Ref>& refs, const Split& s, std::vector<Ref>& left, std::vector<Ref>& right) const {
        for (const Ref& r : refs) {
            if (r.box.hi[s.axis] <= s.pos) {
                left.push_back(r);
            } else if (r.box.lo[s.axis] >= s.pos) {
                right.push_back(r);
            } else {
                const auto [l, rr] = split_reference(tris_[r.prim], r.box, s.axis, s.pos);
                if (!l.is_empty()) left.push_back({l, r.prim});
                if (!rr.is_empty()) right.push_back({rr, r.prim});
            }
        }
    }

    // A binary tree or a piece of one: its nodes depth-first (a node's left child right after it),
    // and the leaves' triangles, leaf by leaf.
    struct Piece {
        std::vector<BinaryNode> nodes;
        std::vector<std::uint32_t> order;
    };

    // Appends `p`, built on its own with indices from 0, to `out`, as if built there; returns
    // the index of its root.
    static std::uint32_t append(Piece& out, const Piece& p) {
        const auto base = static_cast<std::uint32_t>(out.nodes.size());
        const auto first = static_cast<std::uint32_t>(out.order.size());
        for (BinaryNode n : p.nodes) {
            if (n.leaf) {
                n.first += first;
            } else {
                n.left += base;
                n.right += base;
            }
            out.nodes.push_back(n);
        }
        out.order.insert(out.order.end(), p.order.begin(), p.order.end());
        return base;
    }

    // Builds the subtree of `refs` (consumed) into `out`, which may add at most `budget` references
    // by spatial splits; a split hands what is left of it to its children by their sizes. In a
    // parallel build the children of a large node are built as two tasks, each into a piece of its
    // own, appended in order: the nodes and their indices are the sequential build's.
    std::uint32_t build(Piece& out, std::vector<Ref>&& refs, int depth, double budget) {
        LaneBox bounds = LaneBox::empty(), centres = LaneBox::empty();  // Box3::extend's bits, in lanes
        for (const Ref& r : refs) {
            const LaneBox b{lanes_lo(r), lanes_hi(r)};
            bounds.extend(b);
            centres.extend({b.centre(), b.centre()});
        }
        const Box3 box = bounds.box(), cbox = centres.box();
        const auto index = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.push_back({});
        out.nodes[index].box = box;
        const double a = area(box);
        const std::size_t count = refs.size();
        Split object, split;
        if (count > 1 && depth < kSahDepth) {
            split = object = object_split(refs, a, cbox);
            if (budget >= 1.0 && count >= kSpatialMin && object.axis >= 0 && root_area_ > 0.0 &&
                area(intersection(object.left_box, object.right_box)) > kSplitOverlap * root_area_ &&
                any_reaches_across(refs, box)) {
                const Split spatial = spatial_split(refs, a, box, budget);
                if (spatial.axis >= 0 && spatial.cost < object.cost) split = spatial;
            }
        }
        const bool fits = count <= static_cast<std::size_t>(o_.max_leaf);
        if (count <= 1 || (fits && (split.axis < 0 || leaf_cost(count) <= split.cost))) {
            out.nodes[index].leaf = true;
            out.nodes[index].first = static_cast<std::uint32_t>(out.order.size());
            out.nodes[index].count = static_cast<std::uint32_t>(count);
            for (const Ref& r : refs) out.order.push_back(r.prim);
            return index;
        }
        std::vector<Ref> left, right;
        if (split.spatial) {
            partition_spatial(refs, split, left, right);
            // A side that no part reaches (a straddler's box may cross the plane where the triangle
            // does not): the object split instead, which never leaves a side empty.
            if (left.empty() || right.empty()) {
                left.clear();
                right.clear();
                split = object;
            }
        }
        if (!split.spatial) {
            auto mid = refs.begin() + static_cast<std::ptrdiff_t>(count / 2);  // the object median, where no SAH split applies
            if (split.axis >= 0) {
                const AxisBins bins(cbox.lo[split.axis], cbox.hi[split.axis], o_.bins);
                mid = std::partition(refs.begin(), refs.end(),
                                     [&](const Ref& r) { return bins.bin(r.box.center()[split.axis]) < split.bin; });
            }
            left.assign(refs.begin(), mid);
            right.assign(mid, refs.end());
        }
        std::vector<Ref>().swap(refs);
        const double added = static_cast<double>(left.size() + right.size()) - static_cast<double>(count);
        const double left_over = std::max(0.0, budget - added);
        const double share = static_cast<double>(left.size()) / static_cast<double>(left.size() + right.size());
        std::uint32_t l = 0, r = 0;
        if (o_.threads != 1 && count >= o_.parallel_min) {
            Piece lp, rp;
            tbb::task_group group;
            group.run([&] { build(lp, std::move(left), depth + 1, left_over * share); });
            build(rp, std::move(right), depth + 1, left_over * (1.0 - share));
            group.wait();
            l = append(out, lp);
            r = append(out, rp);
        } else {
            l = build(out, std::move(left), depth + 1, left_over * share);
            r = build(out, std::move(right), depth + 1, left_over * (1.0 - share));
        }
        out.nodes[index].left = l;
        out.nodes[index].right = r;
        return index;
    }

    std::span<const Triangle> tris_;
    BvhBuildOptions o_;
    Piece tree_;
    double root_area_ = 0.0;
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
        // The children by decreasing box area (ties keep their order). Any-hit traversals take the
        // first child met (bvh_kernels.inl), so an occlusion ray goes first into the largest box, the
        // likeliest to hold an occluder: the order of an occlusion ray's children decides how soon it
        // ends (Ize and Hansen, "RTSAH Traversal Order for Occlusion Rays", EG 2011, whose
        // probability estimate the box area stands in for here). Closest-hit traversals go to the
        // nearest child first; the others wait in this order (docs/INCOHERENT.md, "Sixteenth round").
        std::stable_sort(kids.begin(), kids.begin() + n,
                         [&](std::uint32_t x, std::uint32_t y) { return area(bn[x].box) > area(bn[y].box); });
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
        if (out_.leaves.size() >= kMaxLeaves)
            throw Error("bvh: more leaves than a child word can address (2^28); raise max_leaf or lower split_budget");
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
    tree.references = builder.order().size();
    tree.mean_leaf_triangles = double(tree.references) / double(tree.leaves.size());
    tree.mean_leaf_depth = double(collapser.leaf_depths()) / double(tree.leaves.size());
    return tree;
}

}  // namespace cellrt::detail
