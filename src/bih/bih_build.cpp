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
// (no indirection): per node one pass bins all three axes (the SAH's centre bins computed for the
// three at once, in four-float vectors), and one partitions the range and bounds the two children's
// centres and boxes, which their own decisions then need; the cost sweeps visit non-empty bins only.
// Large ranges are built as parallel tasks (kernel/subtree.hpp keeps the layout independent of the
// thread count), and the largest are also binned by several threads in blocks combined in order, as
// are the passes over all triangles before and after the tree's.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "kernel/box_lanes.hpp"
#include "kernel/subtree.hpp"
#include "bih_tree.hpp"

namespace cellrt::detail {
namespace {

constexpr std::size_t kParallelMin = 4096;
// The passes over all triangles of a parallel build are cut in blocks of this many, and the passes
// over a range on several threads (binning and partition, range_pass_min_ below) in blocks of
// kRangeBlock.
constexpr std::size_t kBlock = 16384;
constexpr std::size_t kRangeBlock = 4096;
constexpr float kInf = std::numeric_limits<float>::infinity();

// The SAH's bins per axis (its costs and largest leaf are parameters: BihBuildParams).
constexpr int kSahBins = 32;
static_assert(kSahBins <= 32, "a bin per bit of the occupied bins' mask");

// The SAH's measure of a node's cell cut on one axis, as a BIH cuts its children's: the surface area,
// or for a flat cell (all triangles on a line, no area) the length. The other axes' extents are
// computed once per node, in the arithmetic of a whole box's, so the same bits.
class CellMeasure {
public:
    explicit CellMeasure(const Box3& cell) : empty_(cell.is_empty()) {
        for (int a = 0; a < 3; ++a) {
            length_[a] = cell.hi[a] - cell.lo[a];
            extent_[a] = double(cell.hi[a]) - cell.lo[a];
        }
        flat_ = !(operator()(0, cell.lo.x, cell.hi.x) > 0.0);
    }
    // The measure of the cell with [lo, hi] on axis `a`.
    double operator()(int a, float lo, float hi) const {
        if (flat_) {
            float length[3] = {length_[0], length_[1], length_[2]};
            length[a] = hi - lo;
            return double(length[0]) + length[1] + length[2];
        }
        if (empty_ || lo > hi) return 0.0;
        double e[3] = {extent_[0], extent_[1], extent_[2]};
        e[a] = double(hi) - lo;
        return 2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
    }

private:
    bool empty_, flat_ = false;
    float length_[3];
    double extent_[3];
};

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
static_assert(sizeof(Item) == 28 && offsetof(Item, box.hi) == 12);

// The SAH bin of a centre on each axis (kernel/box_lanes.hpp). The origin is the least centre of the
// node, so the product is never negative; but it is NaN on an axis not binned (scale 0) whose centres
// overflowed (coordinates past about 1.7e38: their sums, and the extent, are infinite), which the
// guarded form puts in bin 0 (unguarded, its conversion gave a bin far out of range: a crash, found
// by audit, 2026-12-07).
I4 bins_of(F4 centre, F4 origin, F4 scale) { return lane_bins_guarded(centre, origin, scale, F4{} + float(kSahBins - 1)); }

// The order in which a pass meets the triangles of a range: by ascending or descending position.
enum class Order { ascending, descending };

// The bounds of the centres and boxes of one side of a partition. Box3::extend keeps its bound for an
// equal value (std::min, std::max), which matters for +0 against -0 only: met in ascending position,
// triangles are taken by that rule; met in descending position, an equal value replaces the bound, so
// that both keep the value of the lowest position.
struct Bounds {
    F4 centre_lo = F4{} + kInf, centre_hi = F4{} - kInf, lo = F4{} + kInf, hi = F4{} - kInf;

    template <Order order>
    void take(const Item& t) {
        const F4 l = lanes_lo(t), h = lanes_hi(t), c = (l + h) * 0.5f;
        lo = lower<order>(lo, l);
        hi = higher<order>(hi, h);
        centre_lo = lower<order>(centre_lo, c);
        centre_hi = higher<order>(centre_hi, c);
    }
    // The operand order makes each one instruction (minps, maxps) with the rule for equal values.
    template <Order order>
    static F4 lower(F4 bound, F4 v) {
        if constexpr (order == Order::ascending) return v < bound ? v : bound;
        else return bound < v ? bound : v;
    }
    template <Order order>
    static F4 higher(F4 bound, F4 v) {
        if constexpr (order == Order::ascending) return bound < v ? v : bound;
        else return v < bound ? bound : v;
    }
    // Takes the bounds of triangles that come after this one's, as a pass in ascending order would.
    void merge(const Bounds& later) {
        lo = lower<Order::ascending>(lo, later.lo);
        hi = higher<Order::ascending>(hi, later.hi);
        centre_lo = lower<Order::ascending>(centre_lo, later.centre_lo);
        centre_hi = higher<Order::ascending>(centre_hi, later.centre_hi);
    }
    void store(Range& r) const {
        r.centres = {{centre_lo[0], centre_lo[1], centre_lo[2]}, {centre_hi[0], centre_hi[1], centre_hi[2]}};
        r.objects = {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
    }
};

// The SAH bins of a range on the three axes: per bin its triangles' count and extent on its axis,
// and per axis a bit per non-empty bin, so that the cost sweeps visit those only.
struct Bins {
    std::uint32_t count[3][kSahBins] = {}, occupied[3] = {};
    float lo[3][kSahBins], hi[3][kSahBins];

    Bins() {
        std::fill_n(&lo[0][0], 3 * kSahBins, kInf);
        std::fill_n(&hi[0][0], 3 * kSahBins, -kInf);
    }
    // One pass bins all three axes, the centres' bins computed for the three at once.
    void add(std::span<const Item> items, F4 origin, F4 scale) {
        for (const Item& t : items) {
            const I4 k = bins_of(lanes_centre(t), origin, scale);
            for (int a = 0; a < 3; ++a) {
                ++count[a][k[a]];
                occupied[a] |= 1u << k[a];
                hi[a][k[a]] = std::max(hi[a][k[a]], t.box.hi[a]);
                lo[a][k[a]] = std::min(lo[a][k[a]], t.box.lo[a]);
            }
        }
    }
    // Adds the bins of the triangles after this one's: an extent keeps its value against an equal one,
    // so the bins are those of one pass over both.
    void append(const Bins& later) {
        for (int a = 0; a < 3; ++a) {
            occupied[a] |= later.occupied[a];
            for (int k = 0; k < kSahBins; ++k) {
                count[a][k] += later.count[a][k];
                hi[a][k] = std::max(hi[a][k], later.hi[a][k]);
                lo[a][k] = std::min(lo[a][k], later.lo[a][k]);
            }
        }
    }
};

class BihBuilder {
public:
    BihBuilder(std::span<const Triangle> tris, const BihBuildParams& p) : tris_(tris), p_(p) {}

    BihTree build() {
        BihTree tree;
        auto run = [&] { build_into(tree); };
        run_build(p_.threads, run);
        return tree;
    }

private:
    // The whole build. Besides the tree's tasks, the passes over all triangles (their boxes and the
    // root's bounds before, the reordered copy after) run in blocks on several threads, so that they
    // do not bound a parallel build's speed-up (Amdahl): bounds are taken per block and combined in
    // block order, which keeps the bits of one pass (Bounds), so the tree is the same at any count.
    void build_into(BihTree& tree) {
        const std::size_t n = tris_.size();
        items_.resize(n);
        if (p_.threads != 1) {
            // The threads asked for (all cores for 0), even beyond the machine's: the tree is the same.
            const std::size_t threads = p_.threads != 0 ? p_.threads : static_cast<std::size_t>(build_concurrency(0));
            range_pass_min_ = std::max(p_.parallel_pass_min, n / threads + 1);
        }
        std::vector<Bounds> blocks((n + kBlock - 1) / kBlock);
        for_blocks(n, [&](std::size_t begin, std::size_t end) {
            Bounds& b = blocks[begin / kBlock];
            for (std::size_t i = begin; i < end; ++i) {
                items_[i] = {tris_[i].bounds(), static_cast<std::uint32_t>(i)};
                b.take<Order::ascending>(items_[i]);
            }
        });
        Bounds all;
        for (const Bounds& b : blocks) all.merge(b);
        Range root{0, static_cast<std::uint32_t>(n), {}, {}, {}, {}, 0};
        all.store(root);
        root.box = root.objects;
        if (n == 0) root.box = Box3{Vec3(0.f), Vec3(0.f)};
        root.grid = root.box;
        tree.bounds = root.box;
        // The reordered copy's arrays are fresh pages, faulted in as they are first written (1.6 ms
        // for Sibenik's 75,000 triangles); a parallel build takes them on a thread that the top
        // levels, one node at a time, leave idle.
        auto make_arrays = [&] {
            tree.triangles.resize(n);
            tree.prims.resize(n);
        };
        std::unique_ptr<Subtree<BihNode>> top;
        if (p_.threads == 1) {
            top = subtree(root);
            make_arrays();
        } else {
            tbb::task_group pages;
            pages.run(make_arrays);
            top = subtree(root);
            pages.wait();
        }
        tree.nodes = {BihNode{}, BihNode::leaf(0, 0)};
        std::vector<std::uint32_t> no_indices;
        flatten(*top, 0, tree.nodes, no_indices, BihNode::kMaxIndex, "BIH", p_.threads != 1);
        for_blocks(n, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) {
                tree.triangles[i] = tris_[items_[i].triangle];
                tree.prims[i] = items_[i].triangle;
            }
        });
    }

    // Calls body(begin, end) for [0, n) in blocks of `size`: on several threads in a parallel build
    // (within its arena), in order on one. No block's work may depend on another's.
    template <class Body>
    void for_blocks(std::size_t n, Body&& body, std::size_t size = kBlock) const {
        const std::size_t count = (n + size - 1) / size;
        auto block = [&](std::size_t b) { body(b * size, std::min(n, (b + 1) * size)); };
        if (p_.threads == 1 || count < 2) {
            for (std::size_t b = 0; b < count; ++b) block(b);
            return;
        }
        tbb::parallel_for(std::size_t{0}, count, block);
    }

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
    // sides non-empty), with the clip planes at the two sides' extents on `a`, and each side's bounds.
    template <class GoesLeft>
    Decision split_at(const Range& r, int a, GoesLeft&& goes_left) {
        Bounds left, right;
        const std::uint32_t mid = r.size() >= range_pass_min_ ? partition_in_blocks(r, goes_left, left, right)
                                                              : partition(r, goes_left, left, right);
        Decision d;
        d.kind = Kind::split;
        d.axis = a;
        d.left = d.right = r;
        d.left.end = mid;
        d.right.begin = mid;
        left.store(d.left);
        right.store(d.right);
        d.left_clip = d.left.objects.hi[a];
        d.right_clip = d.right.objects.lo[a];
        d.left.box.hi[a] = std::min(d.left.box.hi[a], d.left_clip);
        d.right.box.lo[a] = std::max(d.right.box.lo[a], d.right_clip);
        d.left.depth = d.right.depth = r.depth + 1;
        return d;
    }

    // Hoare's partition (Quicksort, 1962), step for step libstdc++'s std::partition (which the first
    // builder called), bounding each side in the same pass; returns the first right position. Left
    // triangles are met in ascending final position and right ones in descending: the right side's
    // bounds take equal values (+0 and -0) from the lower position, as a scan in ascending order does,
    // so the planes' bits are those of one ascending pass over each side.
    template <class GoesLeft>
    std::uint32_t partition(const Range& r, GoesLeft& goes_left, Bounds& left, Bounds& right) {
        Item* first = items_.data() + r.begin;
        Item* last = items_.data() + r.end;
        for (;;) {
            for (; first != last && goes_left(*first); ++first) left.take<Order::ascending>(*first);
            if (first == last) break;
            --last;
            for (; first != last && !goes_left(*last); --last) right.take<Order::descending>(*last);
            if (first == last) {  // *first, which goes right, stays where it is
                right.take<Order::descending>(*first);
                break;
            }
            std::iter_swap(first, last);
            left.take<Order::ascending>(*first);
            right.take<Order::descending>(*last);
            ++first;
        }
        return static_cast<std::uint32_t>(first - items_.data());
    }

    // The same order and bounds on several threads. Hoare's loop swaps the j-th right-goer met from
    // the left with the j-th left-goer met from the right, and every one of those lies left of `mid`
    // (the number of left-goers) and right of it respectively; the rest stay. So: count each block's
    // left-goers (their flags kept), rank the misplaced triangles by those counts, note where each
    // rank's left-goer lies, swap the pairs (all independent), and bound the two sides block by block,
    // combined in block order as one ascending pass would. Hence the tree is the same at any thread
    // count (Bih.SameHierarchyBytesAtAnyThreadCount and Bih.PartitionOnSeveralThreadsKeepsTheFirstOfEqualZeros).
    template <class GoesLeft>
    std::uint32_t partition_in_blocks(const Range& r, GoesLeft& goes_left, Bounds& left, Bounds& right) {
        Item* items = items_.data() + r.begin;
        const std::size_t n = r.size(), blocks = (n + kRangeBlock - 1) / kRangeBlock;
        const auto block_end = [&](std::size_t b) { return std::min(n, (b + 1) * kRangeBlock); };
        std::vector<std::uint8_t> goes(n);
        std::vector<std::size_t> lefts(blocks);
        for_blocks(
            n,
            [&](std::size_t begin, std::size_t end) {
                std::size_t count = 0;
                for (std::size_t i = begin; i < end; ++i) count += goes[i] = goes_left(items[i]) ? 1 : 0;
                lefts[begin / kRangeBlock] = count;
            },
            kRangeBlock);
        std::size_t mid = 0;
        for (std::size_t c : lefts) mid += c;
        // Per block: the rank of its first misplaced triangle: right-goers left of mid counted from the
        // left, left-goers from mid on counted from the right.
        std::vector<std::size_t> low_rank(blocks), high_rank(blocks);
        std::size_t misplaced = 0;
        for (std::size_t b = 0; b < blocks; ++b) {
            low_rank[b] = misplaced;
            const std::size_t begin = b * kRangeBlock, end = std::min(block_end(b), mid);
            if (begin >= end) continue;
            if (end == block_end(b)) misplaced += (end - begin) - lefts[b];
            else
                for (std::size_t i = begin; i < end; ++i) misplaced += goes[i] ^ 1u;
        }
        std::size_t seen = 0;
        for (std::size_t b = blocks; b-- > 0;) {
            high_rank[b] = seen;
            const std::size_t begin = std::max(b * kRangeBlock, mid), end = block_end(b);
            if (begin >= end) continue;
            if (begin == b * kRangeBlock) seen += lefts[b];
            else
                for (std::size_t i = begin; i < end; ++i) seen += goes[i];
        }
        std::vector<std::uint32_t> partner(misplaced);  // positions within the range (< 2^30)
        for_blocks(
            n,
            [&](std::size_t begin, std::size_t end) {
                std::size_t rank = high_rank[begin / kRangeBlock];
                for (std::size_t i = end; i-- > std::max(begin, mid);)
                    if (goes[i]) partner[rank++] = static_cast<std::uint32_t>(i);
            },
            kRangeBlock);
        for_blocks(
            n,
            [&](std::size_t begin, std::size_t end) {
                std::size_t rank = low_rank[begin / kRangeBlock];
                for (std::size_t i = begin; i < std::min(end, mid); ++i)
                    if (!goes[i]) std::swap(items[i], items[partner[rank++]]);
            },
            kRangeBlock);
        std::vector<Bounds> left_blocks(blocks), right_blocks(blocks);
        for_blocks(
            n,
            [&](std::size_t begin, std::size_t end) {
                Bounds &l = left_blocks[begin / kRangeBlock], &rt = right_blocks[begin / kRangeBlock];
                for (std::size_t i = begin; i < end; ++i) {
                    if (i < mid) l.take<Order::ascending>(items[i]);
                    else rt.take<Order::ascending>(items[i]);
                }
            },
            kRangeBlock);
        for (std::size_t b = 0; b < blocks; ++b) {
            left.merge(left_blocks[b]);
            right.merge(right_blocks[b]);
        }
        return r.begin + static_cast<std::uint32_t>(mid);
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

        const CellMeasure measure(r.box);
        const double cell_measure = measure(0, r.box.lo.x, r.box.hi.x);
        double best_cost = kInf, best_weight = kInf;
        int best_axis = -1, best_bin = 0;
        // An axis with no extent, too little to bin or an infinite one (centres past the floats' range),
        // is binned at scale 0 (all in bin 0) and skipped.
        bool binned[3];
        F4 origin{}, scale{};
        for (int a = 0; a < 3; ++a) {
            const float extent = centres.hi[a] - centres.lo[a];
            origin[a] = centres.lo[a];
            scale[a] = kSahBins / extent;
            binned[a] = extent > 0.f && extent < kInf && std::isfinite(scale[a]);
            if (!binned[a]) scale[a] = 0.f;
        }
        const Bins bins = bin(r, origin, scale);
        for (int a = 0; a < 3; ++a) {
            if (!binned[a]) continue;
            // Sweep the non-empty bins from the right for the right sides' counts and extents, then
            // from the left. An empty bin changes neither: as a split it ties with the non-empty bin
            // before it, which wins, and the right side beyond a bin is that beyond the next non-empty
            // one (small nodes, the most numerous, have mostly empty bins).
            double right_cost[kSahBins];
            std::uint32_t n = 0;
            float right_lo = kInf;
            for (std::uint32_t rest = bins.occupied[a] & ~1u; rest != 0;) {
                const int k = std::bit_width(rest) - 1;
                rest &= ~(1u << k);
                n += bins.count[a][k];
                right_lo = std::min(right_lo, bins.lo[a][k]);
                right_cost[k] = n * measure(a, std::max(r.box.lo[a], right_lo), r.box.hi[a]);
            }
            n = 0;
            float left_hi = -kInf;
            for (std::uint32_t rest = bins.occupied[a];;) {
                const int k = std::countr_zero(rest);
                rest &= rest - 1;
                if (rest == 0) break;  // the last non-empty bin: every triangle would be left
                n += bins.count[a][k];
                left_hi = std::max(left_hi, bins.hi[a][k]);
                // The cost rises with the children's weight (positive factors, monotone rounding): one
                // no lighter than the best's cannot cost less, and is not costed.
                const double weight = n * measure(a, r.box.lo[a], std::min(r.box.hi[a], left_hi)) + right_cost[std::countr_zero(rest)];
                if (!(weight < best_weight)) continue;
                const double cost = p_.traversal_cost + p_.intersection_cost * weight / cell_measure;
                if (cost < best_cost) best_cost = cost, best_weight = weight, best_axis = a, best_bin = k;
            }
        }
        // A leaf when no split beats testing every triangle, up to sah_max_leaf triangles; beyond, the
        // cheapest split even so (a leaf that large would be tested by every ray that reaches it).
        const bool leaf_is_cheaper = !(best_cost < p_.intersection_cost * r.size());
        if (best_axis < 0 || (leaf_is_cheaper && r.size() <= static_cast<std::uint32_t>(p_.sah_max_leaf)))
            return Decision{};
        return split_at(r, best_axis, [&](const Item& t) { return bins_of(lanes_centre(t), origin, scale)[best_axis] <= best_bin; });
    }

    // The range's bins. A range of range_pass_min_ triangles or more is binned by several threads, in
    // blocks of kRangeBlock combined in block order: the bins of one pass.
    Bins bin(const Range& r, F4 origin, F4 scale) const {
        const std::span<const Item> items(items_.data() + r.begin, r.size());
        Bins bins;
        if (r.size() < range_pass_min_) {
            bins.add(items, origin, scale);
            return bins;
        }
        std::vector<Bins> blocks((items.size() + kRangeBlock - 1) / kRangeBlock);
        for_blocks(
            items.size(),
            [&](std::size_t begin, std::size_t end) {
                blocks[begin / kRangeBlock].add(items.subspan(begin, end - begin), origin, scale);
            },
            kRangeBlock);
        for (const Bins& block : blocks) bins.append(block);
        return bins;
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
        if (d.kind == Kind::leaf) {
            sequential_from(d, r, *out, 0);
            return out;
        }
        out->nodes[0] = BihNode::inner(d.axis, d.left_clip, d.right_clip, 0);
        if (d.kind == Kind::cut) {
            // An empty-space cut keeps every triangle in one child: that child goes on as a subtree of
            // its own, whose splits below are tasks again, beside a piece holding the empty leaf. (Built
            // in this task to the bottom, a cut near the root left one thread most of the tree: on
            // Sibenik the build's task tree allowed 2.3 threads' worth of parallelism, 8.3 now.)
            auto empty = std::make_unique<Subtree<BihNode>>();
            empty->nodes = {BihNode::leaf(0, 0)};
            auto full = subtree(d.left);
            out->left = d.cut_keeps_left ? std::move(full) : std::move(empty);
            out->right = d.cut_keeps_left ? std::move(empty) : std::move(full);
            return out;
        }
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
    // The smallest range whose passes run on several threads: in a parallel build, one of more than
    // its share of the triangles (n / threads: above it the build's tasks are fewer than its threads,
    // and a range's partition would hold the others up), and of parallel_pass_min at least. Smaller
    // ranges run their passes on one thread, which is less work (the partition in blocks takes four
    // passes over its range, Hoare's one). The threads are those asked for, so that a test asking
    // for four reaches the second level on a machine of two cores.
    std::size_t range_pass_min_ = std::numeric_limits<std::size_t>::max();
    std::vector<Item> items_;
};

}  // namespace

BihTree build_bih(std::span<const Triangle> triangles, const BihBuildParams& params) {
    if (triangles.size() > BihNode::kMaxIndex) throw Error("BIH: at most 2^30 triangles are supported");
    return BihBuilder(triangles, params).build();
}

}  // namespace cellrt::detail
