// BIH builder (Wächter & Keller 2006, section 2.2).
//
// The split candidate comes from the global heuristic: a grid cell that starts as the scene box and
// is only ever halved on its own longest axis; the candidate plane is its midpoint, whatever the
// node's box. Triangles are partitioned in place by the centre of their box; the left clip plane is
// the largest coordinate of the left triangles, the right one the smallest of the right triangles.
// When every triangle falls on one side, the grid cell is halved towards them and the split retried
// without emitting a node, unless enough of the node is empty on the other side: then an empty-space
// node is emitted, its empty child's plane at infinity. A node becomes a leaf at `leaf_size`
// triangles, at `max_depth`, or when the grid cell can no longer be halved.
//
// With `split=sah` the plane comes instead from the surface area heuristic over kSahBins bins of the
// triangles' centres on each axis (MacDonald & Booth 1990; binned as in Wald, "On fast Construction
// of SAH-based Bounding Volume Hierarchies", 2007). A BIH child's cell is its parent's cell cut on the
// split axis only, at the largest (left) or smallest (right) extent of its triangles, so that is the
// cell each candidate is costed with. Empty space is still cut first, and the node stays a leaf when
// no split is cheaper than testing its triangles.
//
// Nothing is duplicated: the triangle array is reordered and leaves are ranges of it, so memory is
// known in advance. The builder reorders records of box and triangle index in place, read in order
// (no indirection): per node one pass bins all three axes, one partitions, and one bounds the two
// children's centres and boxes, which their own decisions then need. Large ranges are built as
// parallel tasks (kernel/subtree.hpp keeps the layout independent of the thread count).
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "kernel/subtree.hpp"
#include "bih_tree.hpp"

namespace cellrt::detail {
namespace {

constexpr std::size_t kParallelMin = 4096;
constexpr float kInf = std::numeric_limits<float>::infinity();

// The SAH's bins per axis (its costs and largest leaf are parameters: BihBuildParams).
constexpr int kSahBins = 32;

double area(const Box3& b) {
    if (b.is_empty()) return 0.0;
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return 2.0 * (x * y + y * z + z * x);
}

int longest_axis(const Box3& b) {
    const Vec3 e = b.extent();
    return e.x >= e.y ? (e.x >= e.z ? 0 : 2) : (e.y >= e.z ? 1 : 2);
}

struct Range {
    std::uint32_t begin = 0, end = 0;
    Box3 box;   // the node's clip box: where its triangles may lie
    Box3 grid;  // the global heuristic's candidate cell
    Box3 centres, objects;  // bounds of the range's triangle centres and boxes
    int depth = 0;
    std::uint32_t size() const { return end - begin; }
};

// A triangle as the builder moves it: its box and its scene index.
struct Item {
    Box3 box;
    std::uint32_t triangle;
    Vec3 centre() const { return box.center(); }
};

class BihBuilder {
public:
    BihBuilder(std::span<const Triangle> tris, const BihBuildParams& p) : tris_(tris), p_(p) {
        items_.resize(tris.size());
        for (std::uint32_t i = 0; i < items_.size(); ++i) items_[i] = {tris[i].bounds(), i};
    }

    BihTree build() {
        BihTree tree;
        Range root{0, static_cast<std::uint32_t>(tris_.size()), {}, {}, {}, {}, 0};
        for (const Item& it : items_) {
            root.objects.extend(it.box);
            root.centres.extend(it.centre());
        }
        root.box = root.objects;
        if (tris_.empty()) root.box = Box3{Vec3(0.f), Vec3(0.f)};
        root.grid = root.box;
        tree.bounds = root.box;
        std::unique_ptr<Subtree<BihNode>> top;
        auto run = [&] { top = subtree(root); };
        if (p_.threads == 1) {
            run();
        } else {
            tbb::task_arena arena(build_concurrency(p_.threads));
            arena.execute(run);
        }
        tree.nodes = {BihNode{}, BihNode::leaf(0, 0)};
        std::vector<std::uint32_t> no_indices;
        flatten(*top, 0, tree.nodes, no_indices, BihNode::kMaxIndex, "BIH");
        tree.triangles.reserve(tris_.size());
        tree.prims.reserve(tris_.size());
        for (const Item& it : items_) {
            tree.triangles.push_back(tris_[it.triangle]);
            tree.prims.push_back(it.triangle);
        }
        return tree;
    }

private:
    enum class Kind { leaf, split, cut };
    struct Decision {
        Kind kind = Kind::leaf;
        int axis = 0;
        float left_clip = 0.f, right_clip = 0.f;
        Range left, right;  // split: both; cut: the occupied one only (the other child is empty)
        bool cut_keeps_left = true;
    };

    Decision decide(Range r) {
        Decision d;
        if (r.size() <= static_cast<std::uint32_t>(p_.leaf_size) || r.depth >= p_.max_depth) return d;
        const Box3 &centres = r.centres, &objects = r.objects;
        if (p_.split == BihSplit::sah) return decide_sah(r);
        for (;;) {
            const int a = longest_axis(r.grid);
            const float split = 0.5f * (r.grid.lo[a] + r.grid.hi[a]);
            if (!(r.grid.lo[a] < split && split < r.grid.hi[a])) return d;  // the cell cannot be halved further
            const float width = r.box.hi[a] - r.box.lo[a];
            if (centres.hi[a] <= split) {  // all left: cut the empty right part, or halve the cell
                if (r.box.hi[a] - objects.hi[a] > static_cast<float>(p_.empty_cut) * width)
                    return cut(r, a, objects.hi[a], kInf, true);
                r.grid.hi[a] = split;
                continue;
            }
            if (centres.lo[a] > split) {  // all right
                if (objects.lo[a] - r.box.lo[a] > static_cast<float>(p_.empty_cut) * width)
                    return cut(r, a, -kInf, objects.lo[a], false);
                r.grid.lo[a] = split;
                continue;
            }
            Decision d = split_at(r, a, [&](const Item& t) { return t.centre()[a] <= split; });
            d.left.grid.hi[a] = split;
            d.right.grid.lo[a] = split;
            return d;
        }
    }

    // Partitions the range in place into the triangles for which `goes_left` holds and the rest (both
    // sides non-empty), with the clip planes at the two sides' extents on `a`, and bounds each side.
    template <class GoesLeft>
    Decision split_at(const Range& r, int a, GoesLeft&& goes_left) {
        const auto mid_it = std::partition(items_.begin() + r.begin, items_.begin() + r.end, goes_left);
        const auto mid = static_cast<std::uint32_t>(mid_it - items_.begin());
        Decision d;
        d.kind = Kind::split;
        d.axis = a;
        d.left = d.right = r;
        d.left.end = mid;
        d.right.begin = mid;
        for (Range* side : {&d.left, &d.right}) {
            Box3 centres, objects;
            for (std::uint32_t i = side->begin; i < side->end; ++i) {
                objects.extend(items_[i].box);
                centres.extend(items_[i].centre());
            }
            side->centres = centres;
            side->objects = objects;
        }
        d.left_clip = d.left.objects.hi[a];
        d.right_clip = d.right.objects.lo[a];
        d.left.box.hi[a] = std::min(d.left.box.hi[a], d.left_clip);
        d.right.box.lo[a] = std::max(d.right.box.lo[a], d.right_clip);
        d.left.depth = d.right.depth = r.depth + 1;
        return d;
    }

    // The SAH split (see the top of this file).
    Decision decide_sah(const Range& r) {
        const Box3 &centres = r.centres, &objects = r.objects;
        // Empty space first: the side of the cell with the largest empty fraction, beyond empty_cut.
        int cut_axis = -1;
        bool cut_high = false;
        double cut_fraction = p_.empty_cut;
        for (int a = 0; a < 3; ++a) {
            const double width = double(r.box.hi[a]) - r.box.lo[a];
            if (!(width > 0.0)) continue;
            const double high = (double(r.box.hi[a]) - objects.hi[a]) / width, low = (double(objects.lo[a]) - r.box.lo[a]) / width;
            if (high > cut_fraction) cut_axis = a, cut_high = true, cut_fraction = high;
            if (low > cut_fraction) cut_axis = a, cut_high = false, cut_fraction = low;
        }
        if (cut_axis >= 0)
            return cut_high ? cut(r, cut_axis, objects.hi[cut_axis], kInf, true)
                            : cut(r, cut_axis, -kInf, objects.lo[cut_axis], false);

        struct Bin {
            std::uint32_t count = 0;
            float hi = -kInf, lo = kInf;  // the extent of the bin's triangles on the axis
        };
        // A flat cell (all triangles on a line) has no area: its length serves instead.
        const bool flat = !(area(r.box) > 0.0);
        auto measure = [flat](const Box3& b) { return flat ? double(b.hi.x - b.lo.x) + (b.hi.y - b.lo.y) + (b.hi.z - b.lo.z) : area(b); };
        const double cell_measure = measure(r.box);
        double best_cost = kInf;
        int best_axis = -1, best_bin = 0;
        // One pass bins all three axes; an axis with no extent, or too little to bin, is binned at
        // scale 0 (all in bin 0) and skipped below.
        bool binned[3];
        float scales[3];
        for (int a = 0; a < 3; ++a) {
            const float extent = centres.hi[a] - centres.lo[a];
            scales[a] = kSahBins / extent;
            binned[a] = extent > 0.f && std::isfinite(scales[a]);
            if (!binned[a]) scales[a] = 0.f;
        }
        Bin all_bins[3][kSahBins];
        for (std::uint32_t i = r.begin; i < r.end; ++i) {
            const Item& t = items_[i];
            const Vec3 c = t.centre();
            for (int a = 0; a < 3; ++a) {
                Bin& b = all_bins[a][bin_of(c[a], centres.lo[a], scales[a])];
                ++b.count;
                b.hi = std::max(b.hi, t.box.hi[a]);
                b.lo = std::min(b.lo, t.box.lo[a]);
            }
        }
        for (int a = 0; a < 3; ++a) {
            if (!binned[a]) continue;
            const Bin* bins = all_bins[a];
            // Sweep from the right for the right sides' counts and extents, then from the left. An empty
            // bin changes neither: its costs are its neighbour's, copied, and as a split it ties with the
            // bin before it, which wins (small nodes have mostly empty bins).
            double right_cost[kSahBins];
            std::uint32_t count = 0;
            float right_lo = kInf;
            for (int k = kSahBins - 1; k > 0; --k) {
                if (bins[k].count == 0 && k < kSahBins - 1) {
                    right_cost[k] = right_cost[k + 1];
                    continue;
                }
                count += bins[k].count;
                right_lo = std::min(right_lo, bins[k].lo);
                Box3 cell = r.box;
                cell.lo[a] = std::max(cell.lo[a], right_lo);
                right_cost[k] = count * measure(cell);
            }
            count = 0;
            float left_hi = -kInf;
            for (int k = 0; k < kSahBins - 1; ++k) {
                if (bins[k].count == 0) continue;
                count += bins[k].count;
                left_hi = std::max(left_hi, bins[k].hi);
                if (count == r.size()) continue;
                Box3 cell = r.box;
                cell.hi[a] = std::min(cell.hi[a], left_hi);
                const double cost = p_.traversal_cost + p_.intersection_cost * (count * measure(cell) + right_cost[k + 1]) / cell_measure;
                if (cost < best_cost) best_cost = cost, best_axis = a, best_bin = k;
            }
        }
        // A leaf when no split beats testing every triangle, up to sah_max_leaf triangles; beyond, the
        // cheapest split even so (a leaf that large would be tested by every ray that reaches it).
        const bool leaf_is_cheaper = !(best_cost < p_.intersection_cost * r.size());
        if (best_axis < 0 || (leaf_is_cheaper && r.size() <= static_cast<std::uint32_t>(p_.sah_max_leaf)))
            return Decision{};
        const float lo = centres.lo[best_axis], scale = kSahBins / (centres.hi[best_axis] - lo);
        return split_at(r, best_axis, [&](const Item& t) { return bin_of(t.centre()[best_axis], lo, scale) <= best_bin; });
    }

    static int bin_of(float centre, float lo, float scale) {
        return static_cast<int>(std::clamp((centre - lo) * scale, 0.f, static_cast<float>(kSahBins - 1)));
    }

    // An empty-space node: every triangle in one child, bounded by `left_clip`/`right_clip`; the
    // other child is an empty leaf whose plane at infinity no ray reaches.
    static Decision cut(const Range& r, int a, float left_clip, float right_clip, bool keeps_left) {
        Decision d;
        d.kind = Kind::cut;
        d.axis = a;
        d.left_clip = left_clip;
        d.right_clip = right_clip;
        d.cut_keeps_left = keeps_left;
        d.left = r;
        d.left.depth = r.depth + 1;
        if (keeps_left) d.left.box.hi[a] = left_clip;
        else d.left.box.lo[a] = right_clip;
        return d;
    }

    std::unique_ptr<Subtree<BihNode>> subtree(const Range& r) {
        auto out = std::make_unique<Subtree<BihNode>>();
        out->nodes.resize(1);
        if (r.size() < kParallelMin || p_.threads == 1) {
            sequential(r, *out, 0);
            return out;
        }
        const Decision d = decide(r);
        if (d.kind != Kind::split) {  // leaves and cuts of large ranges: continue in this task
            sequential_from(d, r, *out, 0);
            return out;
        }
        out->nodes[0] = BihNode::inner(d.axis, d.left_clip, d.right_clip, 0);
        tbb::task_group group;
        group.run([&] { out->left = subtree(d.left); });
        out->right = subtree(d.right);
        group.wait();
        return out;
    }

    void sequential(const Range& r, Subtree<BihNode>& out, std::uint32_t slot) { sequential_from(decide(r), r, out, slot); }

    void sequential_from(const Decision& d, const Range& r, Subtree<BihNode>& out, std::uint32_t slot) {
        if (d.kind == Kind::leaf) {
            out.nodes[slot] = BihNode::leaf(r.begin, r.size());
            return;
        }
        const auto pair = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.resize(out.nodes.size() + 2);
        out.nodes[slot] = BihNode::inner(d.axis, d.left_clip, d.right_clip, pair);
        if (d.kind == Kind::split) {
            sequential(d.left, out, pair);
            sequential(d.right, out, pair + 1);
            return;
        }
        out.nodes[d.cut_keeps_left ? pair + 1 : pair] = BihNode::leaf(0, 0);
        sequential(d.left, out, d.cut_keeps_left ? pair : pair + 1);
    }

    std::span<const Triangle> tris_;
    const BihBuildParams& p_;
    std::vector<Item> items_;
};

}  // namespace

BihTree build_bih(std::span<const Triangle> triangles, const BihBuildParams& params) {
    if (triangles.size() > BihNode::kMaxIndex) throw Error("BIH: at most 2^30 triangles are supported");
    return BihBuilder(triangles, params).build();
}

}  // namespace cellrt::detail
