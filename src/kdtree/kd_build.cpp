// SAH kd-tree builder.
//
// Large nodes (more than `sweep_below` references) are split by min-max binning (Shevtsov et al.
// 2007, section 3.2): per axis, one histogram counts where reference boxes start and one where they
// end; prefix sums give the exact counts left and right of every bin boundary, where the SAH is
// evaluated. Smaller nodes get the exact split of the event sweep (Wald & Havran 2006, sections 4.2
// and 4.3: every start, end and planar position of a reference box a candidate), found without
// sorting every event: min-max bins give, for every candidate in a bin, a lower bound of its SAH cost
// (the counts at the bin's edges, the areas at its ends), and only the events of the bins whose bound
// is not above the cost of a candidate already found are sorted and swept (branch and bound). The
// choice, ties included, is exactly the full sweep's, so the tree is the one W&H's sweep builds, at
// the price of one binning pass, a few gathering passes and small sorts per node. Straddling
// triangles are clipped to each child cell ("perfect splits", W&H section 4.1) so that child boxes
// are tight, where that pays (clip_ratio: those small against the cell get their box cut to the
// child cells instead); references are partitioned into per-thread buffers indexed by depth, so
// that no node allocates. Clipping: kd_clip.hpp; the SAH and the search for the cheapest
// candidate: kd_sah.hpp.
//
// Parallelism: the two children of a large node are built as separate tasks, each into its own node
// array; a final pass lays the pieces out depth-first. The layout depends only on the tree, never on
// which thread built what, so the bytes are the same at any thread count.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "cellrt/error.hpp"
#include "kernel/binning.hpp"
#include "kernel/subtree.hpp"
#include "kd_clip.hpp"
#include "kd_event.hpp"
#include "kd_sah.hpp"
#include "kd_tree.hpp"

namespace cellrt::detail {

int KdBuildParams::depth_limit(std::size_t triangles) const {
    if (max_depth > 0) return std::min(max_depth, kKdMaxDepth);
    const double auto_depth = 8.0 + 1.3 * std::log2(static_cast<double>(std::max<std::size_t>(triangles, 1)));
    return std::min(static_cast<int>(auto_depth), kKdMaxDepth);
}

namespace {

using namespace kdbuild;

// Nodes with fewer references are built by one task.
constexpr std::size_t kParallelMin = 2048;
// Passes over large nodes in parallel builds (KdBuildParams::parallel_pass_min) work in blocks of
// this many references whose results are combined in block order: the same counts and the same
// reference order as one thread's.
constexpr std::size_t kBlock = 16384;
// Nodes with at least this many references give their children buffers of their own (sequential()).
constexpr std::size_t kOwnedMin = 65536;
// The exact search keeps sorted events (W&H's O(N log N) sweep) in nodes this small; larger ones are
// bounded by bins first.
constexpr std::size_t kEventsBelow = 256;
// Bins per axis of the exact search's bounds: about one per 8 references, within these limits.
constexpr int kBoundBinsMin = 4, kBoundBinsMax = 256;
// How far, in bins, the bounds reach beyond a bin's edges (see best_split_exact).
constexpr double kEdgeMargin = 1.0 / 64;

// What the builder knows about one node: its cell, its path, and its references either as boxes
// (binning, bounded exact search) or as sorted event lists (sweep). Moved, never copied (a moved
// vector keeps its storage): `refs` may view `owned`, `events` may view `owned_events`; otherwise
// they lie in a per-thread buffer.
struct Work {
    Box3 cell;
    Box3 bounds;  // boxes: the union of the references' boxes
    int depth = 0;
    int bad_refines = 0;
    bool events_mode = false;
    std::span<Ref> refs;
    std::vector<Ref> owned;
    std::span<const Event> events[3];  // per axis, sorted
    std::size_t triangles = 0;         // events mode: one reference per triangle
    std::vector<Event> owned_events;

    Work() = default;
    Work(Work&&) = default;
    Work& operator=(Work&&) = default;
    std::size_t size() const { return events_mode ? triangles : refs.size(); }
};

enum class Side : std::uint8_t { both, left, right };

// Per-thread buffers of the builder. The recursion is depth-first, so a thread works on at most
// one node per depth at a time: buffers indexed by depth serve every node at that depth in turn.
struct Scratch {
    std::vector<Side> side;  // per triangle (and a spare slot); Side::both outside split_events
    std::vector<std::uint32_t> straddling_storage;
    std::span<const std::uint32_t> straddling;
    // Events of the clipped straddlers, per child and axis: sorted lists in their storage.
    std::vector<Event> clipped_storage[2][3];
    std::span<const Event> clipped[2][3];
    // By depth: the events of a node that switches from boxes to events, and the children's
    // references or events of the node being split (by the children's depth).
    std::array<std::vector<Event>, kKdMaxDepth + 1> converted;
    std::array<std::array<std::vector<Ref>, 2>, kKdMaxDepth + 1> children;
    std::array<std::array<std::vector<Event>, 2>, kKdMaxDepth + 1> children_events;
    std::vector<std::uint32_t> starts, ends;  // histograms, per axis
    std::vector<Event> events;                // the bounded search's gathered events of one axis
};

// The exact search's bins of one axis: the first holds what lies at or below the cell's low plane,
// the last what lies at or above its high plane (no candidate lies there: W&H take planes inside
// the cell only), the ones between are min-max bins over the references' tight bounds.
struct EdgeBins {
    AxisBins inner;
    float cell_lo = 0.f, cell_hi = 0.f;
    int count = 3;
    int bin(float x) const { return x <= cell_lo ? 0 : x >= cell_hi ? count - 1 : 1 + inner.bin(x); }
};

class KdBuilder {
public:
    KdBuilder(std::span<const Triangle> tris, const KdBuildParams& p)
        : tris_(tris), p_(p), depth_limit_(p.depth_limit(tris.size())), scratch_([n = tris.size()] {
              Scratch s;
              s.side.assign(n + 1, Side::both);  // and a spare slot (classify)
              return s;
          }) {}

    KdTree build() {
        KdTree tree;
        tree.triangle_count = tris_.size();
        Work root;
        root.owned.reserve(tris_.size());
        for (std::uint32_t i = 0; i < tris_.size(); ++i) {
            const Box3 b = tris_[i].bounds();
            root.cell.extend(b);
            root.owned.push_back({i, b});
        }
        root.refs = root.owned;
        if (tris_.empty()) root.cell = Box3{Vec3(0.f), Vec3(0.f)};
        root.bounds = root.cell;
        tree.bounds = root.cell;
        tree.nodes.resize(2);
        auto run = [&] {
            const std::unique_ptr<Subtree<KdNode>> top = subtree(std::move(root));
            flatten(*top, 0, tree.nodes, tree.indices, KdNode::kMaxIndex, "kd-tree", p_.threads != 1);
        };
        run_build(p_.threads, run);
        return tree;
    }

private:
    struct Decision {
        bool leaf = true;
        Split split;
        std::size_t size = 0;  // references in the node
    };

    // Builds the subtree of `w`; large nodes split into two tasks. Its cost (the SAH estimate of the
    // work for a ray through the cell) is kept for retraction.
    std::unique_ptr<Subtree<KdNode>> subtree(Work&& w) {
        auto out = std::make_unique<Subtree<KdNode>>();
        out->nodes.resize(1);
        if (w.size() < kParallelMin || p_.threads == 1) {
            out->cost = sequential(std::move(w), *out, 0, scratch_.local());
            return out;
        }
        const Decision d = decide(w, scratch_.local());
        if (d.leaf) {
            out->cost = leaf(w, *out, 0);
            return out;
        }
        out->nodes[0] = KdNode::inner(d.split.axis, d.split.pos, 0);
        const Box3 cell = w.cell;
        Work left, right;
        split(std::move(w), d.split, left, right, {left.owned, right.owned, left.owned_events, right.owned_events},
              scratch_.local());
        tbb::task_group group;
        group.run([&] { out->left = subtree(std::move(left)); });
        out->right = subtree(std::move(right));
        group.wait();
        out->cost = split_cost(cell, d.split, out->left->cost, out->right->cost);
        if (retract(out->cost, d.size)) {
            Subtree<KdNode> single;
            single.nodes.resize(1);
            gather(*out, single.indices);
            single.cost = finish_leaf(single, 0, 0);
            *out = std::move(single);
        }
        return out;
    }

    double sequential(Work&& w, Subtree<KdNode>& out, std::uint32_t slot, Scratch& scratch) {
        const Decision d = decide(w, scratch);
        if (d.leaf) return leaf(w, out, slot);
        const Box3 cell = w.cell;
        const std::size_t nodes_before = out.nodes.size(), indices_before = out.indices.size();
        const auto pair = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.resize(out.nodes.size() + 2);
        out.nodes[slot] = KdNode::inner(d.split.axis, d.split.pos, pair);
        Work left, right;
        auto& refs = scratch.children[w.depth + 1];
        auto& events = scratch.children_events[w.depth + 1];
        // A large node's children own their references, freed once they are split in turn: a
        // per-depth buffer would keep the largest node of its depth for the rest of the build.
        const bool owned = !w.events_mode && w.size() >= kOwnedMin;
        split(std::move(w), d.split, left, right,
              {owned ? left.owned : refs[0], owned ? right.owned : refs[1], events[0], events[1]}, scratch);
        const double left_cost = sequential(std::move(left), out, pair, scratch);
        const double right_cost = sequential(std::move(right), out, pair + 1, scratch);
        const double cost = split_cost(cell, d.split, left_cost, right_cost);
        if (!retract(cost, d.size)) return cost;
        out.nodes.resize(nodes_before);
        return finish_leaf(out, slot, indices_before);
    }

    // Writes the leaf of `w` to nodes[slot]; returns its cost.
    double leaf(const Work& w, Subtree<KdNode>& out, std::uint32_t slot) const {
        const std::size_t first = out.indices.size();
        if (w.events_mode) {
            for (const Event e : w.events[0])
                if (e.type() != kEnd) out.indices.push_back(e.triangle());
        } else {
            for (const Ref& r : w.refs) out.indices.push_back(r.triangle);
        }
        return finish_leaf(out, slot, first);
    }

    // Makes indices[first..] (the triangles of the leaf at nodes[slot], maybe repeated) sorted and
    // distinct and writes the leaf node; returns its cost.
    double finish_leaf(Subtree<KdNode>& out, std::uint32_t slot, std::size_t first) const {
        const auto begin = out.indices.begin() + static_cast<std::ptrdiff_t>(first);
        std::sort(begin, out.indices.end());
        out.indices.erase(std::unique(begin, out.indices.end()), out.indices.end());
        const std::size_t count = out.indices.size() - first;
        out.nodes[slot] = KdNode::leaf(static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(count));
        return p_.intersection_cost * static_cast<double>(count);
    }

    double split_cost(const Box3& cell, const Split& s, double left_cost, double right_cost) const {
        const auto [pl, pr] = SahCost(cell, p_).probabilities(s.axis, s.pos);
        return p_.traversal_cost + pl * left_cost + pr * right_cost;
    }

    // Mitsuba's retraction: a subtree that, built, is no cheaper than one leaf becomes that leaf.
    bool retract(double subtree_cost, std::size_t triangles) const {
        return p_.retract && subtree_cost >= p_.intersection_cost * static_cast<double>(triangles);
    }

    static void gather(const Subtree<KdNode>& s, std::vector<std::uint32_t>& out) {
        out.insert(out.end(), s.indices.begin(), s.indices.end());
        if (s.left) gather(*s.left, out);
        if (s.right) gather(*s.right, out);
    }

    // Leaf or split (W&H section 5 termination, with Mitsuba's bad-refinement rule: a split costing
    // more than a leaf is tolerated a few times on a path, since a later split may pay for it).
    // Switches `w` to events where the sweep takes over and counts a bad refinement in it.
    Decision decide(Work& w, Scratch& scratch) const {
        Decision d;
        const std::size_t n = w.size();
        d.size = n;
        const SahCost sah(w.cell, p_);
        if (n > static_cast<std::size_t>(p_.leaf_size) && w.depth < depth_limit_ && sah.splittable()) {
            const bool exact = p_.method == KdBuildMethod::sweep ||
                               (p_.method == KdBuildMethod::hybrid && n <= static_cast<std::size_t>(p_.sweep_below));
            if (exact && n <= kEventsBelow && !w.events_mode) to_events(w, scratch.converted[w.depth]);
            d.split = w.events_mode ? best_split_sweep(w, sah)
                      : exact       ? best_split_exact(w, sah, scratch)
                                    : best_split_binned(w, sah, scratch);
            if (d.split.axis >= 0) {
                const double leaf_cost = sah.leaf(n);
                d.leaf = false;
                if (d.split.cost >= leaf_cost) {
                    if ((d.split.cost > 4.0 * leaf_cost && n < 16) || w.bad_refines >= p_.max_bad_refines) d.leaf = true;
                    else ++w.bad_refines;
                }
            }
        }
        return d;
    }

    // Switches `w` from boxes to events, sorted once here (W&H section 4.2), kept in `buffer`.
    static void to_events(Work& w, std::vector<Event>& buffer) {
        const std::size_t n = w.refs.size();
        if (buffer.size() < 6 * n) buffer.resize(6 * n);  // at most two events per reference and axis
        for (int a = 0; a < 3; ++a) {
            const std::span<Event> list = std::span(buffer).subspan(2 * n * a, 2 * n);
            std::size_t count = 0;
            for (const Ref& r : w.refs) count += put_events(a, r.triangle, r.box, &list[count]);
            std::sort(list.begin(), list.begin() + static_cast<std::ptrdiff_t>(count));
            w.events[a] = list.first(count);
        }
        w.triangles = n;
        w.events_mode = true;
        w.refs = {};
        std::vector<Ref>().swap(w.owned);
    }

    // Writes the events of a reference with box `box` on axis `a` to out[0] and maybe out[1];
    // returns how many: 1 for a box flat on the axis, else 2. Both slots are written, branch-free.
    static std::size_t put_events(int a, std::uint32_t tri, const Box3& box, Event* out) {
        const bool planar = box.lo[a] == box.hi[a];
        out[0] = Event(box.lo[a], planar ? kPlanar : kStart, tri);
        out[1] = Event(box.hi[a], kEnd, tri);
        return planar ? 1 : 2;
    }

    // W&H section 4.3: one pass per axis over the sorted events, position by position (sweep_position).
    static Split best_split_sweep(const Work& w, const SahCost& sah) {
        SplitSearch search(sah);
        for (int a = 0; a < 3; ++a) {
            const float lo = w.cell.lo[a], hi = w.cell.hi[a];
            if (!(lo < hi)) continue;
            const std::span<const Event> ev = w.events[a];
            std::ptrdiff_t nl = 0, nr = static_cast<std::ptrdiff_t>(w.triangles);
            for (std::size_t i = 0; i < ev.size();) sweep_position(ev, i, a, lo, hi, sah, search, nl, nr);
        }
        return search.best();
    }

    // Bins of `bins` per axis over the references' tight bounds (an axis without extent: one bin).
    static std::array<AxisBins, 3> axis_bins(const Work& w, int bins) {
        const Box3 tight = intersection(w.bounds, w.cell);
        return {AxisBins(tight.lo[0], tight.hi[0], bins), AxisBins(tight.lo[1], tight.hi[1], bins),
                AxisBins(tight.lo[2], tight.hi[2], bins)};
    }

    // Per axis, how many reference boxes start and end in each bin: scratch.starts and .ends hold
    // axis a's histogram of bins[a].count bins at a * stride.
    template <class Bins>
    static void count(std::span<const Ref> refs, const std::array<Bins, 3>& bins, std::size_t stride,
                      std::uint32_t* starts, std::uint32_t* ends) {
        for (const Ref& r : refs)
            for (int a = 0; a < 3; ++a) {
                ++starts[a * stride + static_cast<std::size_t>(bins[a].bin(r.box.lo[a]))];
                ++ends[a * stride + static_cast<std::size_t>(bins[a].bin(r.box.hi[a]))];
            }
    }
    template <class Bins>
    void histograms(const Work& w, const std::array<Bins, 3>& bins, std::size_t stride, Scratch& scratch) const {
        scratch.starts.assign(3 * stride, 0u);
        scratch.ends.assign(3 * stride, 0u);
        if (!parallel_pass(w)) return count(w.refs, bins, stride, scratch.starts.data(), scratch.ends.data());
        const std::size_t blocks = (w.refs.size() + kBlock - 1) / kBlock;
        std::vector<std::uint32_t> starts(blocks * 3 * stride, 0u), ends(blocks * 3 * stride, 0u);
        tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
            count(block(w.refs, b), bins, stride, &starts[b * 3 * stride], &ends[b * 3 * stride]);
        });
        for (std::size_t b = 0; b < blocks; ++b)
            for (std::size_t i = 0; i < 3 * stride; ++i) {
                scratch.starts[i] += starts[b * 3 * stride + i];
                scratch.ends[i] += ends[b * 3 * stride + i];
            }
    }

    bool parallel_pass(const Work& w) const { return p_.threads != 1 && !w.events_mode && w.refs.size() >= p_.parallel_pass_min; }
    static std::span<Ref> block(std::span<Ref> refs, std::size_t b) {
        return refs.subspan(b * kBlock, std::min(kBlock, refs.size() - b * kBlock));
    }

    // Shevtsov et al. section 3.2: min-max binning over the references' tight bounds; the candidates
    // are the bin boundaries.
    Split best_split_binned(const Work& w, const SahCost& sah, Scratch& scratch) const {
        SplitSearch search(sah);
        const int bins = p_.bins;
        const auto axes = axis_bins(w, bins);
        const auto stride = static_cast<std::size_t>(bins);
        histograms(w, axes, stride, scratch);
        const Box3 tight = intersection(w.bounds, w.cell);
        for (int a = 0; a < 3; ++a) {
            if (axes[a].count == 1) continue;  // no extent
            const std::uint32_t* starts = &scratch.starts[a * stride];
            const std::uint32_t* ends = &scratch.ends[a * stride];
            const float lo = axes[a].lo, hi = tight.hi[a];
            std::ptrdiff_t nl = 0, nr = static_cast<std::ptrdiff_t>(w.refs.size());
            for (int i = 1; i < bins; ++i) {
                nl += starts[i - 1];
                nr -= ends[i - 1];
                const float pos = lo + (hi - lo) * (static_cast<float>(i) / static_cast<float>(bins));
                if (!(w.cell.lo[a] < pos && pos < w.cell.hi[a])) continue;
                search.offer(a, pos, sah.areas(a, pos), nl, nr, true);
            }
        }
        return search.best();
    }

    // The split W&H's sweep chooses (see the top of this file): bins bound every candidate's cost,
    // the bin with the lowest bound is swept for a first cost, then every bin whose bound is not above
    // it is swept, axis by axis and in order, so that the first of equal costs wins as in the full sweep.
    Split best_split_exact(const Work& w, const SahCost& sah, Scratch& scratch) const {
        const std::size_t n = w.refs.size();
        const int inner = sah.nonnegative() ? std::clamp(static_cast<int>(n / 2), kBoundBinsMin, kBoundBinsMax) : 1;
        const auto inner_bins = axis_bins(w, inner);
        std::array<EdgeBins, 3> axes;
        for (int a = 0; a < 3; ++a) axes[a] = {inner_bins[a], w.cell.lo[a], w.cell.hi[a], inner_bins[a].count + 2};
        const auto stride = static_cast<std::size_t>(inner + 2);
        histograms(w, axes, stride, scratch);
        const Box3 tight = intersection(w.bounds, w.cell);
        // Per axis and bin, the references sure to be left (starting in an earlier bin) and right
        // (ending in a later one) of any candidate in the bin, and the bound of the bin's costs.
        std::vector<std::uint32_t>& left_of = scratch.starts;  // prefix sums in place
        std::vector<std::uint32_t>& right_of = scratch.ends;   // suffix sums in place
        constexpr double kInf = std::numeric_limits<double>::infinity();
        std::array<double, 3 * (kBoundBinsMax + 2)> bound;
        std::size_t best_bin = bound.size();
        for (int a = 0; a < 3; ++a) {
            std::uint32_t* l = &left_of[a * stride];
            std::uint32_t* r = &right_of[a * stride];
            double* b = &bound[a * stride];
            const int count = axes[a].count;
            std::uint32_t sum = 0;
            for (int k = 0; k < count; ++k) sum += std::exchange(l[k], sum);
            sum = 0;
            for (int k = count - 1; k >= 0; --k) sum += std::exchange(r[k], sum);
            std::fill(b, b + count, kInf);  // the edge bins hold no candidate
            const float cell_lo = w.cell.lo[a], cell_hi = w.cell.hi[a];
            if (!(cell_lo < cell_hi)) continue;
            // A candidate of inner bin j lies between its edges, give or take the float rounding of
            // bin(): three roundings of relative 2^-24 each, at most 256 * 2^-22 of a bin, far below
            // kEdgeMargin.
            const AxisBins& in = axes[a].inner;
            const double width = (double(tight.hi[a]) - in.lo) / in.count;
            for (int j = 0; j < in.count; ++j) {
                const int k = j + 1;
                const double x_lo = j == 0 ? cell_lo : std::max<double>(cell_lo, in.lo + (j - kEdgeMargin) * width);
                const double x_hi =
                    j == in.count - 1 ? cell_hi : std::min<double>(cell_hi, in.lo + (j + 1 + kEdgeMargin) * width);
                const auto nl = static_cast<std::ptrdiff_t>(l[k]), nr = static_cast<std::ptrdiff_t>(r[k]);
                b[k] = std::min(sah.estimate(sah.areas_at(a, x_lo), nl, nr), sah.estimate(sah.areas_at(a, x_hi), nl, nr));
                if (best_bin == bound.size() || b[k] < bound[best_bin]) best_bin = a * stride + static_cast<std::size_t>(k);
            }
        }
        double limit = kInf;
        std::uint8_t chosen[kBoundBinsMax + 2];
        if (inner > 1 && best_bin < bound.size()) {
            const auto a = static_cast<int>(best_bin / stride);
            const std::size_t k = best_bin % stride;
            std::fill(chosen, chosen + stride, std::uint8_t{0});
            chosen[k] = 1;
            SplitSearch first(sah);
            sweep_bins(w, sah, a, axes[a], chosen, &left_of[a * stride], &right_of[a * stride], first, scratch);
            if (first.best().axis >= 0) limit = first.best().cost * (1.0 + 0x1p-40);
        }
        SplitSearch search(sah);
        for (int a = 0; a < 3; ++a) {
            bool any = false;
            for (int k = 0; k < axes[a].count; ++k) {
                chosen[k] = bound[a * stride + k] <= limit;
                any |= chosen[k] != 0;
            }
            if (any) sweep_bins(w, sah, a, axes[a], chosen, &left_of[a * stride], &right_of[a * stride], search, scratch);
        }
        return search.best();
    }

    // W&H section 4.3 over the events of the chosen bins of axis `a`, sorted: at each position, the
    // ends and planars there leave the right side, the plane is evaluated with the planars on either
    // side, then the starts and planars join the left side. Entering a bin, the counts are the bin's
    // `left_of` and `right_of` (plus the references with events in it, on the right).
    static void sweep_bins(const Work& w, const SahCost& sah, int a, const EdgeBins& axis, const std::uint8_t* chosen,
                           const std::uint32_t* left_of, const std::uint32_t* right_of, SplitSearch& search,
                           Scratch& scratch) {
        std::vector<Event>& ev = scratch.events;
        ev.clear();
        for (const Ref& r : w.refs) {
            const float lo = r.box.lo[a], hi = r.box.hi[a];
            const bool planar = lo == hi;
            if (chosen[axis.bin(lo)]) ev.emplace_back(lo, planar ? kPlanar : kStart, r.triangle);
            if (!planar && chosen[axis.bin(hi)]) ev.emplace_back(hi, kEnd, r.triangle);
        }
        std::sort(ev.begin(), ev.end());
        const float lo = w.cell.lo[a], hi = w.cell.hi[a];
        const auto n = static_cast<std::ptrdiff_t>(w.refs.size());
        std::ptrdiff_t nl = 0, nr = n;
        int bin = -1;
        for (std::size_t i = 0; i < ev.size();) {
            const int k = axis.bin(ev[i].pos());
            if (k != bin) {
                bin = k;
                nl = left_of[k];
                nr = k == 0 ? n : static_cast<std::ptrdiff_t>(right_of[k - 1]);  // ending in bin k or later
            }
            sweep_position(ev, i, a, lo, hi, sah, search, nl, nr);
        }
    }

    // What an event adds to a run's count of ends (low half) and starts (high half), by type.
    static constexpr std::uint64_t kRunCount[3] = {1, 0, std::uint64_t{1} << 32};  // kEnd, kPlanar, kStart

    // One position of the sweep (W&H section 4.3): the run of events from ev[i] at one position and
    // class, after which `i` points. Its ends and planars leave the right side, the plane is offered
    // with the planars on either side, then its starts and planars join the left side. Inlined: it is
    // the sweep's inner loop.
    [[gnu::always_inline]] static void sweep_position(std::span<const Event> ev, std::size_t& i, int a, float lo,
                                                      float hi, const SahCost& sah, SplitSearch& search,
                                                      std::ptrdiff_t& nl, std::ptrdiff_t& nr) {
        const std::size_t first = i;
        const Event run_end = ev[i].next_position();
        // The run's ends and starts counted in one word, ends in the low half, starts in the high
        // (a list holds fewer than 2^32 events); the planars are the rest of the run.
        std::uint64_t counts = 0;
        do counts += kRunCount[ev[i].type()];
        while (++i < ev.size() && ev[i] < run_end);
        const auto ends = static_cast<std::ptrdiff_t>(counts & 0xffffffffu);
        const auto starts = static_cast<std::ptrdiff_t>(counts >> 32);
        const auto planars = static_cast<std::ptrdiff_t>(i - first) - ends - starts;
        const std::ptrdiff_t leaving = ends + planars, joining = starts + planars;
        nr -= leaving;
        const float pos = ev[first].pos();
        if (lo < pos && pos < hi) {
            const auto areas = sah.areas(a, pos);
            const float split = pos == 0.f ? run_position(ev.subspan(first, i - first)) : pos;
            search.offer(a, split, areas, nl + planars, nr, true);
            if (planars > 0) search.offer(a, split, areas, nl, nr + planars, false);  // else the same cost
        }
        nl += joining;
    }

    // The position of a run of events at equal floats as the float order has it: that of its
    // first event, the one with the smallest key. (The run's events differ only at zero: -0 or +0.)
    static float run_position(std::span<const Event> run) {
        return std::min_element(run.begin(), run.end(), [](Event a, Event b) { return a.key() < b.key(); })->pos();
    }

    // The parts of a straddling triangle in the two children of `cell`: clipped (perfect splits), or
    // its box cut to each child cell (every ancestor cell contains the child cell, so the cut needs
    // no earlier box).
    std::pair<Box3, Box3> child_boxes(std::uint32_t tri, const Box3& cell, const Split& s) const {
        const Box3 b = tris_[tri].bounds();
        if (p_.perfect_splits && clip_pays(intersection(b, cell), cell, s.axis))
            return clipped_child_bounds(tris_[tri], cell, s.axis, s.pos);
        Box3 lcell = cell, rcell = cell;
        lcell.hi[s.axis] = rcell.lo[s.axis] = s.pos;
        return {intersection(b, lcell), intersection(b, rcell)};
    }

    // Whether to clip (perfect splits, Wald & Havran 2006, section 4.1) a straddler whose box within
    // the cell is `b`: only where the box spans at least `clip_ratio` of the cell on an axis other
    // than the split axis. For a triangle small against the cell the cut box is nearly as tight as
    // the clipped one (this rule and its default are measured in docs/BUILD_SPEED.md, not taken
    // from the paper). `clip_ratio` 0 clips every straddler.
    bool clip_pays(const Box3& b, const Box3& cell, int axis) const {
        for (int a = 0; a < 3; ++a)
            if (a != axis && !(b.hi[a] - b.lo[a] < p_.clip_ratio * (cell.hi[a] - cell.lo[a]))) return true;
        return false;
    }

    // Where a split writes the children's references or events (grown, never shrunk).
    struct ChildBuffers {
        std::vector<Ref>&left_refs, &right_refs;
        std::vector<Event>&left_events, &right_events;
    };

    // Splits `w` (consumed) into the children's Work.
    void split(Work&& w, const Split& s, Work& left, Work& right, ChildBuffers out, Scratch& scratch) const {
        left.cell = right.cell = w.cell;
        left.cell.hi[s.axis] = right.cell.lo[s.axis] = s.pos;
        for (Work* c : {&left, &right}) {
            c->depth = w.depth + 1;
            c->bad_refines = w.bad_refines;
            c->events_mode = w.events_mode;
        }
        if (w.events_mode) split_events(w, s, left, right, out.left_events, out.right_events, scratch);
        else split_refs(w, s, left, right, out.left_refs, out.right_refs);
        w = Work{};
    }

    // A box ending at or before the plane goes left, one starting at or after it right, one lying in
    // it by `planar_left`, and a straddler's clipped parts to the sides they reach (W&H section 4.4).
    void split_refs(const Work& w, const Split& s, Work& left, Work& right, std::vector<Ref>& left_refs,
                    std::vector<Ref>& right_refs) const {
        // Reserved, not resized: a buffer's pages become resident only as far as references fill them.
        const std::size_t n = w.refs.size();
        left_refs.clear();
        right_refs.clear();
        left_refs.reserve(n);
        right_refs.reserve(n);
        Box3 lbounds, rbounds;
        if (!parallel_pass(w)) {
            const auto [lb, rb] = partition(w.refs, w.cell, s, left_refs, right_refs);
            lbounds = lb, rbounds = rb;
        } else {
            // Each block into lists of its own, then the lists back to back in block order.
            const std::size_t blocks = (n + kBlock - 1) / kBlock;
            std::vector<std::vector<Ref>> lparts(blocks), rparts(blocks);
            std::vector<std::pair<Box3, Box3>> bounds(blocks);
            tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
                const std::span<const Ref> refs = block(w.refs, b);
                lparts[b].reserve(refs.size());
                rparts[b].reserve(refs.size());
                bounds[b] = partition(refs, w.cell, s, lparts[b], rparts[b]);
            });
            for (std::size_t b = 0; b < blocks; ++b) {
                left_refs.insert(left_refs.end(), lparts[b].begin(), lparts[b].end());
                right_refs.insert(right_refs.end(), rparts[b].begin(), rparts[b].end());
                lbounds.extend(bounds[b].first);
                rbounds.extend(bounds[b].second);
            }
        }
        left.refs = left_refs;
        right.refs = right_refs;
        left.bounds = lbounds;
        right.bounds = rbounds;
    }

    // split_refs() of `refs`, appended to the two lists; returns the bounds of what each received.
    std::pair<Box3, Box3> partition(std::span<const Ref> refs, const Box3& cell, const Split& s,
                                    std::vector<Ref>& left_refs, std::vector<Ref>& right_refs) const {
        const int a = s.axis;
        Box3 lbounds, rbounds;
        for (const Ref& r : refs) {
            const bool planar_here = r.box.lo[a] == s.pos && r.box.hi[a] == s.pos;
            const bool goes_left = r.box.lo[a] < s.pos || (planar_here && s.planar_left);
            const bool goes_right = r.box.hi[a] > s.pos || (planar_here && !s.planar_left);
            if (goes_left && goes_right) {
                const auto [lb, rb] = child_boxes(r.triangle, cell, s);
                if (!lb.is_empty()) left_refs.push_back({r.triangle, lb}), lbounds.extend(lb);
                if (!rb.is_empty()) right_refs.push_back({r.triangle, rb}), rbounds.extend(rb);
            } else if (goes_left) {
                left_refs.push_back(r);
                lbounds.extend(r.box);
            } else {
                right_refs.push_back(r);
                rbounds.extend(r.box);
            }
        }
        return {lbounds, rbounds};
    }

    // W&H section 4.4: classify triangles by the split axis's events, clip the straddlers to both
    // children and sort only their new events, then one pass per axis hands every one-sided event to
    // its child, merged with the new events, into the children's buffers.
    void split_events(const Work& w, const Split& s, Work& left, Work& right, std::vector<Event>& left_events,
                      std::vector<Event>& right_events, Scratch& scratch) const {
        auto [nl, nr] = classify(w.events[s.axis], s, scratch);
        const auto [clipped_left, clipped_right] = clip_straddlers(w.cell, s, scratch);
        nl += clipped_left;
        nr += clipped_right;
        distribute(w, left, right, left_events, right_events, scratch);
        for (const Event e : w.events[s.axis]) scratch.side[e.triangle()] = Side::both;  // the scratch is reused
        left.triangles = nl;
        right.triangles = nr;
    }

    // Sets the side of every one-sided triangle and lists the straddlers; returns the numbers of
    // left and right triangles. A triangle's end at or before the plane makes it left, its start at
    // or after the plane right, a planar one goes by its position (W&H section 4.4); one that ends
    // after the plane without having been made right straddles it. Branch-free (the sides are
    // unpredictable): an event that decides nothing writes to a spare slot past the triangles.
    static std::pair<std::size_t, std::size_t> classify(std::span<const Event> events, const Split& s,
                                                        Scratch& scratch) {
        // By where the event lies (before, on or after the plane) and its type (end, planar, start).
        const Side decides[3][3] = {{Side::left, Side::left, Side::both},
                                    {Side::left, s.planar_left ? Side::left : Side::right, Side::right},
                                    {Side::both, Side::right, Side::right}};
        std::vector<Side>& side = scratch.side;
        std::vector<std::uint32_t>& straddling = scratch.straddling_storage;
        if (straddling.size() < events.size()) straddling.resize(events.size());
        const auto nowhere = static_cast<std::uint32_t>(side.size() - 1);
        // Positions compared as their integer classes, which order finite floats as the floats do.
        const std::uint32_t plane = Event(s.pos, kEnd, 0).position_class();
        std::size_t nl = 0, nr = 0, straddlers = 0;
        for (const Event e : events) {
            const std::uint32_t pos = e.position_class();
            const std::uint32_t t = e.triangle();
            const std::size_t where = 1 + std::size_t{pos > plane} - std::size_t{pos < plane};
            const Side decided = decides[where][e.type()];
            straddling[straddlers] = t;
            straddlers += std::size_t{e.type() == kEnd} & std::size_t{where == 2} & std::size_t{side[t] == Side::both};
            const std::uint32_t undecided = 0u - std::uint32_t{decided == Side::both};  // a mask: the compiler
            side[(t & ~undecided) | (nowhere & undecided)] = decided;                  // would branch on `?:`
            nl += decided == Side::left;
            nr += decided == Side::right;
        }
        scratch.straddling = std::span(straddling).first(straddlers);
        return {nl, nr};
    }

    // Clips the straddlers to both children into sorted event lists (Scratch::clipped); returns
    // how many reach into the left and the right child.
    std::pair<std::size_t, std::size_t> clip_straddlers(const Box3& cell, const Split& s, Scratch& scratch) const {
        const std::size_t capacity = 2 * scratch.straddling.size();
        for (auto& lists : scratch.clipped_storage)
            for (std::vector<Event>& list : lists)
                if (list.size() < capacity) list.resize(capacity);
        std::size_t reaching[2] = {0, 0}, count[2][3] = {};
        for (const std::uint32_t t : scratch.straddling) {
            const auto [lb, rb] = child_boxes(t, cell, s);
            const Box3* boxes[2] = {&lb, &rb};
            for (int c = 0; c < 2; ++c) {
                const bool reaches = !boxes[c]->is_empty();
                for (int a = 0; a < 3; ++a)
                    count[c][a] += reaches * put_events(a, t, *boxes[c], &scratch.clipped_storage[c][a][count[c][a]]);
                reaching[c] += reaches;
            }
        }
        for (int c = 0; c < 2; ++c)
            for (int a = 0; a < 3; ++a) {
                const std::span<Event> list(scratch.clipped_storage[c][a].data(), count[c][a]);
                sort_events(list);
                scratch.clipped[c][a] = list;
            }
        return {reaching[0], reaching[1]};
    }

    // Sorts the few events a split adds to one list (most hold 2 to 16). Lists of up to 32 are
    // padded with sentinels to a power of two and sorted by Batcher's odd-even merge network
    // (Knuth, TAOCP vol. 3, section 5.3.4): a fixed sequence of compare-exchanges, each a minimum
    // and a maximum without a branch, unlike the unpredictable loop exits of the insertion sort
    // std::sort uses there. No two events of a list are equal, so every sort gives the same list.
    static void sort_events(std::span<Event> list) {
        constexpr std::size_t kByNetwork = 32;
        const std::size_t n = list.size();
        if (n <= 1) return;
        if (n > kByNetwork) return std::sort(list.begin(), list.end());
        Event block[kByNetwork];
        std::copy_n(list.begin(), n, block);
        const std::size_t size = std::bit_ceil(n);
        std::fill(block + n, block + size, Event::sentinel());
        switch (size) {
            case 2: sort_network<2>(block); break;
            case 4: sort_network<4>(block); break;
            case 8: sort_network<8>(block); break;
            case 16: sort_network<16>(block); break;
            default: sort_network<32>(block); break;
        }
        std::copy_n(block, n, list.begin());
    }

    // Batcher's odd-even merge sort of n = 2^k events, unrolled at compile time into a straight
    // sequence of compare-exchanges between fixed slots (network_pairs below).
    template <std::size_t n>
    static void sort_network(Event* e) {
        static constexpr auto pairs = network_pairs<n>();
        [&]<std::size_t... i>(std::index_sequence<i...>) {
            (compare_exchange(e[pairs[i].first], e[pairs[i].second]), ...);
        }(std::make_index_sequence<pairs.size()>{});
    }
    [[gnu::always_inline]] static void compare_exchange(Event& x, Event& y) {
        const Event a = x, b = y;
        const bool swap = b < a;
        x = swap ? b : a;
        y = swap ? a : b;
    }
    // The network's compare-exchanges in order, fn(first, second) for each: runs of p, 2p, ...
    // merged (Knuth's algorithm M).
    template <std::size_t n, class Fn>
    static constexpr void network(Fn&& fn) {
        for (std::size_t p = 1; p < n; p += p)
            for (std::size_t k = p; k >= 1; k /= 2)
                for (std::size_t j = k % p; j + k < n; j += 2 * k)
                    for (std::size_t i = 0; i < k && i + j + k < n; ++i)
                        if ((i + j) / (2 * p) == (i + j + k) / (2 * p)) fn(i + j, i + j + k);
    }
    template <std::size_t n>
    static constexpr std::size_t network_size() {
        std::size_t count = 0;
        network<n>([&](std::size_t, std::size_t) { ++count; });
        return count;
    }
    template <std::size_t n>
    static constexpr auto network_pairs() {
        std::array<std::pair<std::uint8_t, std::uint8_t>, network_size<n>()> out{};
        std::size_t count = 0;
        network<n>([&](std::size_t a, std::size_t b) {
            out[count++] = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b)};
        });
        return out;
    }

    // Per axis, every event of a one-sided triangle goes to its child, leaving room in front for
    // the child's new events, which are then merged in. Each child's three lists lie back to back
    // in its buffer.
    static void distribute(const Work& w, Work& left, Work& right, std::vector<Event>& left_events,
                           std::vector<Event>& right_events, const Scratch& scratch) {
        const auto& [new_left, new_right] = scratch.clipped;
        std::size_t bound[2] = {1, 1};  // one spare slot for the sentinel after the last list
        for (int k = 0; k < 3; ++k) {
            bound[0] += w.events[k].size() + new_left[k].size();
            bound[1] += w.events[k].size() + new_right[k].size();
        }
        if (left_events.size() < bound[0]) left_events.resize(bound[0]);
        if (right_events.size() < bound[1]) right_events.resize(bound[1]);
        std::size_t nl = 0, nr = 0;  // events written so far
        for (int k = 0; k < 3; ++k) {
            const std::size_t left_begin = nl, right_begin = nr;
            nl += new_left[k].size();
            nr += new_right[k].size();
            // Both children receive the event, and the one it belongs to keeps it: no branch on the
            // side, which the sweep order makes unpredictable. (Indices rather than pointers: the
            // compiler turns `pointer += condition` back into a branch.)
            for (const Event e : w.events[k]) {
                const Side sd = scratch.side[e.triangle()];
                left_events[nl] = e;
                nl += sd == Side::left;
                right_events[nr] = e;
                nr += sd == Side::right;
            }
            left.events[k] = merge_in_front(std::span(left_events).subspan(left_begin, nl - left_begin), new_left[k]);
            right.events[k] = merge_in_front(std::span(right_events).subspan(right_begin, nr - right_begin), new_right[k]);
        }
    }

    // `list` holds sorted events after extra.size() free slots, and is followed by one slot that may
    // be overwritten; merges the sorted `extra` in, so that `list` holds all of them sorted. The merge
    // writes behind where it reads and stops when `extra` is used up: what follows is in place.
    // Branch-free: which list the next event comes from is unpredictable.
    static std::span<const Event> merge_in_front(std::span<Event> list, std::span<const Event> extra) {
        Event* const out = list.data();
        out[list.size()] = Event::sentinel();
        std::size_t written = 0, from_list = extra.size(), from_extra = 0;
        while (from_extra < extra.size()) {
            const Event x = out[from_list], y = extra[from_extra];
            const bool take_extra = y < x;
            out[written++] = take_extra ? y : x;
            from_extra += take_extra;
            from_list += !take_extra;
        }
        return list;
    }

    std::span<const Triangle> tris_;
    const KdBuildParams& p_;
    int depth_limit_;
    tbb::enumerable_thread_specific<Scratch> scratch_;
};

}  // namespace

KdTree build_kdtree(std::span<const Triangle> triangles, const KdBuildParams& params) {
    if (triangles.size() > kTriangleMask) throw Error("kd-tree: at most 2^30 triangles are supported");
    return KdBuilder(triangles, params).build();
}

}  // namespace cellrt::detail
