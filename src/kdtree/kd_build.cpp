// SAH kd-tree builder.
//
// Large nodes (more than `sweep_below` references) are split by min-max binning (Shevtsov et al.
// 2007, section 3.2): per axis, one histogram counts where reference boxes start and one where they
// end; prefix sums give the exact counts left and right of every bin boundary, where the SAH is
// evaluated. Smaller nodes use the exact sweep of Wald & Havran (2006, section 4): events (start,
// end, or planar for a box flat on the axis) sorted once per axis, kept sorted through every split by
// partition and merge, so that the build below the switch costs O(N log N). Straddling triangles are
// clipped to each child cell ("perfect splits", W&H section 4.1) so that child boxes are tight.
//
// Speed, without changing a bit of the tree: events are single integers (Event), the recursion
// reuses per-thread buffers by depth instead of allocating per node, the hot loops avoid branches
// whose direction the data decides, and the sweep computes the SAH's divisions only for candidates
// that may win (SplitSearch).
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

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "cellrt/error.hpp"
#include "kernel/subtree.hpp"
#include "kd_tree.hpp"

namespace cellrt::detail {

int KdBuildParams::depth_limit(std::size_t triangles) const {
    if (max_depth > 0) return std::min(max_depth, kKdMaxDepth);
    const double auto_depth = 8.0 + 1.3 * std::log2(static_cast<double>(std::max<std::size_t>(triangles, 1)));
    return std::min(static_cast<int>(auto_depth), kKdMaxDepth);
}

namespace {

constexpr std::uint32_t kTriangleMask = (1u << 30) - 1;
// Nodes with fewer references are built by one task.
constexpr std::size_t kParallelMin = 2048;

// Event types in sweep order at equal positions: ends before planars before starts (W&H section 4.2).
enum EventType : std::uint32_t { kEnd = 0, kPlanar = 1, kStart = 2 };

// An event packed into one integer whose order is the sweep order (position, type, triangle): the
// high half holds the position's float bits mapped to an unsigned integer of the same order (all bits
// of a negative flipped, the sign bit of the rest set), the low half type << 30 | triangle. A
// triangle has one event of each type per axis, so no two events of a list are equal: every correct
// sort or merge of a list gives the same sequence. One difference from the order of floats: that has
// -0 == +0 (and orders the events there by type and triangle), the integers put -0 just before +0;
// the sweep treats both as one position (run_position).
class Event {
public:
    Event() = default;
    Event(float pos, EventType type, std::uint32_t triangle)
        : bits_(std::uint64_t{ordered(pos)} << 32 | type << 30 | triangle) {}

    float pos() const {
        const auto o = static_cast<std::uint32_t>(bits_ >> 32);
        return std::bit_cast<float>(o & kSign ? o & ~kSign : ~o);
    }
    // The ordered position with -0 taken as +0: equal exactly for equal floats.
    std::uint32_t position_class() const {
        const auto o = static_cast<std::uint32_t>(bits_ >> 32);
        return o == kNegativeZero ? kSign : o;
    }
    std::uint32_t key() const { return static_cast<std::uint32_t>(bits_); }
    EventType type() const { return static_cast<EventType>(key() >> 30); }
    std::uint32_t triangle() const { return key() & kTriangleMask; }
    friend bool operator<(Event a, Event b) { return a.bits_ < b.bits_; }

    // Greater than every event (their positions are finite): ends a list for a merge without bounds checks.
    static Event sentinel() {
        Event e;
        e.bits_ = ~std::uint64_t{0};
        return e;
    }

private:
    static constexpr std::uint32_t kSign = 1u << 31;
    static constexpr std::uint32_t kNegativeZero = ~kSign;  // ordered(-0.f)
    static std::uint32_t ordered(float f) {
        const auto b = std::bit_cast<std::uint32_t>(f);
        return b & kSign ? ~b : b | kSign;
    }
    std::uint64_t bits_;
};

struct Ref {
    std::uint32_t triangle;
    Box3 box;
};

// std::nextafter(f, -inf) and std::nextafter(f, +inf), without the library call (which takes a
// third of the clipping time).
float float_step_down(float f) {
    if (f == 0.f) return -std::numeric_limits<float>::denorm_min();
    if (std::isnan(f) || f == -std::numeric_limits<float>::infinity()) return f;
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0.f ? bits - 1 : bits + 1);
}
float float_step_up(float f) { return -float_step_down(-f); }

// Rounds a double down / up to the next float, then one more float step outward: the clipped
// polygon is computed in double, and this keeps its float box conservative.
float float_below(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = float_step_down(f);
    return float_step_down(f);
}
float float_above(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) < x) f = float_step_up(f);
    return float_step_up(f);
}

// A triangle clipped to axis-aligned half-spaces one at a time (Sutherland-Hodgman, in double
// precision). Cutting a convex polygon by a plane adds at most one vertex: 3 + 6 planes. Each cut
// writes the new polygon into the other of two buffers rather than copying it back, a copy that
// would stall on reading vertices just written piecewise.
class ClippedPolygon {
public:
    explicit ClippedPolygon(const Triangle& t) {
        P* v = buffers_[0];
        v[0] = {t.v0.x, t.v0.y, t.v0.z};
        v[1] = {t.v1.x, t.v1.y, t.v1.z};
        v[2] = {t.v2.x, t.v2.y, t.v2.z};
    }
    ClippedPolygon(const ClippedPolygon& other) : n_(other.n_) {
        std::copy_n(other.buffers_[other.current_], kMaxVertices, buffers_[0]);
    }
    ClippedPolygon& operator=(const ClippedPolygon&) = delete;

    // Keeps the part with c[a] >= plane (`keep_above`) or c[a] <= plane.
    template <bool keep_above>
    void clip(int a, double plane) {
        const P* v = buffers_[current_];
        bool in[kMaxVertices];
        int inside = 0;
        for (int i = 0; i < n_; ++i) {
            in[i] = keep_above ? v[i].c[a] >= plane : v[i].c[a] <= plane;
            inside += in[i];
        }
        if (inside == n_) return;
        // Every vertex and every edge's crossing point is written, and kept by moving on or not:
        // which edges cross is unpredictable, and a branch on it costs more than the arithmetic.
        P* kept = buffers_[current_ ^ 1];
        int m = 0;
        for (int i = 0; i < n_; ++i) {
            const int j = i + 1 == n_ ? 0 : i + 1;
            const P& cur = v[i];
            const P& nxt = v[j];
            kept[m] = cur;
            m += in[i];
            const double s = (plane - cur.c[a]) / (nxt.c[a] - cur.c[a]);
            P& x = kept[m];
            for (int k = 0; k < 3; ++k) x.c[k] = cur.c[k] + s * (nxt.c[k] - cur.c[k]);
            x.c[a] = plane;
            m += in[i] != in[j];
        }
        n_ = m;
        current_ ^= 1;
    }
    void clip_to_slab(int a, const Box3& cell) {
        clip<true>(a, cell.lo[a]);
        clip<false>(a, cell.hi[a]);
    }

    // Bounds rounded outward and cut to `cell`; empty when nothing is left.
    Box3 bounds(const Box3& cell) const {
        if (n_ == 0) return Box3::empty();
        const P* v = buffers_[current_];
        double lo[3], hi[3];
        for (int k = 0; k < 3; ++k) lo[k] = hi[k] = v[0].c[k];
        for (int i = 1; i < n_; ++i)
            for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[i].c[k]), hi[k] = std::max(hi[k], v[i].c[k]);
        Box3 b;
        for (int k = 0; k < 3; ++k) {
            b.lo[k] = std::max(float_below(lo[k]), cell.lo[k]);
            b.hi[k] = std::min(float_above(hi[k]), cell.hi[k]);
        }
        return b;
    }

private:
    static constexpr int kMaxVertices = 9;
    struct P {
        double c[3];
    };
    P buffers_[2][kMaxVertices + 1];  // one spare slot for the last unconditional write
    int current_ = 0;
    int n_ = 3;
};

// Bounds of the parts of `tri` in the two children of `cell` split at `pos` on `axis`: each is the
// triangle clipped to the child cell's six planes in the order x-lo, x-hi, y-lo, ..., z-hi. The two
// children share the planes before the split axis, so that prefix is clipped once for both.
std::pair<Box3, Box3> clipped_child_bounds(const Triangle& tri, const Box3& cell, int axis, float pos) {
    Box3 lcell = cell, rcell = cell;
    lcell.hi[axis] = rcell.lo[axis] = pos;
    ClippedPolygon left(tri);
    for (int a = 0; a < axis; ++a) left.clip_to_slab(a, cell);
    ClippedPolygon right = left;
    left.clip_to_slab(axis, lcell);
    right.clip_to_slab(axis, rcell);
    for (int a = axis + 1; a < 3; ++a) {
        left.clip_to_slab(a, cell);
        right.clip_to_slab(a, cell);
    }
    return {left.bounds(lcell), right.bounds(rcell)};
}

// The SAH of one candidate split of `cell` (W&H section 3): probabilities are the children's
// surface areas over the parent's, from two per-axis factors precomputed per cell.
class SahCost {
public:
    SahCost(const Box3& cell, const KdBuildParams& p) : cell_(cell), p_(p) {
        const double e[3] = {double(cell.hi.x) - cell.lo.x, double(cell.hi.y) - cell.lo.y,
                             double(cell.hi.z) - cell.lo.z};
        for (int a = 0; a < 3; ++a) {
            const double b = e[(a + 1) % 3], c = e[(a + 2) % 3];
            constant_[a] = b * c;
            linear_[a] = b + c;
        }
        half_area_ = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
        scaled_reciprocal_ = p.intersection_cost / half_area_;
    }
    bool splittable() const { return half_area_ > 0.0; }
    double leaf(std::size_t n) const { return p_.intersection_cost * static_cast<double>(n); }
    // Half the surface areas of the two children: the numerators of their probabilities.
    std::pair<double, double> areas(int a, float pos) const {
        const double wl = double(pos) - cell_.lo[a], wr = double(cell_.hi[a]) - pos;
        return {constant_[a] + wl * linear_[a], constant_[a] + wr * linear_[a]};
    }
    // Probabilities that a ray through the cell passes through the left and the right child.
    std::pair<double, double> probabilities(int a, float pos) const {
        const auto [al, ar] = areas(a, pos);
        return {al / half_area_, ar / half_area_};
    }
    double split(std::pair<double, double> areas, std::ptrdiff_t nl, std::ptrdiff_t nr) const {
        const double pl = areas.first / half_area_, pr = areas.second / half_area_;
        return with_bonus(p_.traversal_cost + p_.intersection_cost * (pl * double(nl) + pr * double(nr)), nl, nr);
    }
    // split() without its two divisions: a multiplication by a reciprocal instead. Each of the two
    // is at most eight roundings from the real value of the expression, so with nonnegative terms
    // both lie within a relative 8 * 2^-53 = 2^-50 of it.
    double estimate(std::pair<double, double> areas, std::ptrdiff_t nl, std::ptrdiff_t nr) const {
        const double weighted = areas.first * double(nl) + areas.second * double(nr);
        return with_bonus(p_.traversal_cost + scaled_reciprocal_ * weighted, nl, nr);
    }
    // Whether every term of split() is nonnegative, so that relative rounding errors do not grow.
    bool nonnegative() const {
        return p_.traversal_cost >= 0.0 && p_.intersection_cost >= 0.0 && p_.empty_bonus >= 0.0 && p_.empty_bonus <= 1.0;
    }

private:
    double with_bonus(double cost, std::ptrdiff_t nl, std::ptrdiff_t nr) const {
        return nl == 0 || nr == 0 ? cost * (1.0 - p_.empty_bonus) : cost;
    }

    Box3 cell_;
    const KdBuildParams& p_;
    double constant_[3], linear_[3], half_area_, scaled_reciprocal_;
};

struct Split {
    double cost = std::numeric_limits<double>::infinity();
    int axis = -1;
    float pos = 0.f;
    bool planar_left = true;  // where triangles lying in the plane go
};

// The cheapest of the candidate splits offered; the first of equal costs wins.
//
// The exact cost takes two divisions, the sweep's largest expense. So candidates are screened by
// SahCost::estimate(): it and the exact cost are both within a relative 2^-50 of the real value
// (all magnitudes come from float extents, far from double underflow and overflow), so a candidate
// whose estimate is not below best * (1 + 2^-40) costs more than the best and is dropped unseen.
// The choice is exactly that of costing every candidate exactly.
class SplitSearch {
public:
    explicit SplitSearch(const SahCost& sah) : sah_(sah), screens_(sah.nonnegative()) {}

    // Whether a candidate with this estimate may be cheaper than the best.
    bool may_improve(double estimate) const { return estimate < bound_; }
    void offer(int axis, float pos, std::pair<double, double> areas, std::ptrdiff_t nl, std::ptrdiff_t nr,
               bool planar_left) {
        if (!may_improve(sah_.estimate(areas, nl, nr))) return;
        const double cost = sah_.split(areas, nl, nr);
        if (!(cost < best_.cost)) return;
        best_ = {cost, axis, pos, planar_left};
        if (screens_) bound_ = cost * (1.0 + 0x1p-40);
    }
    const Split& best() const { return best_; }

private:
    const SahCost& sah_;
    bool screens_;
    Split best_;
    double bound_ = std::numeric_limits<double>::infinity();
};

// What the builder knows about one node: its cell, its path, and its references either as boxes
// (binning) or as sorted event lists (sweep). Moved, never copied: `events` may view `owned`.
struct Work {
    Box3 cell;
    int depth = 0;
    int bad_refines = 0;
    bool events_mode = false;
    std::vector<Ref> refs;
    std::span<const Event> events[3];  // per axis, sorted
    std::size_t triangles = 0;         // events mode: one reference per triangle
    std::vector<Event> owned;          // the events' storage, unless a per-thread buffer holds them

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
    // By depth: the events of a node that switches from boxes to events, and the children's events
    // of the node being split (by the children's depth).
    std::array<std::vector<Event>, kKdMaxDepth + 1> converted;
    std::array<std::array<std::vector<Event>, 2>, kKdMaxDepth + 1> children;
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
        root.refs.reserve(tris_.size());
        for (std::uint32_t i = 0; i < tris_.size(); ++i) {
            const Box3 b = tris_[i].bounds();
            root.cell.extend(b);
            root.refs.push_back({i, b});
        }
        if (tris_.empty()) root.cell = Box3{Vec3(0.f), Vec3(0.f)};
        tree.bounds = root.cell;
        std::unique_ptr<Subtree<KdNode>> top;
        auto run = [&] { top = subtree(std::move(root)); };
        if (p_.threads == 1) {
            run();
        } else {
            tbb::task_arena arena(build_concurrency(p_.threads));
            arena.execute(run);
        }
        tree.nodes.resize(2);
        flatten(*top, 0, tree.nodes, tree.indices, KdNode::kMaxIndex, "kd-tree");
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
        split(std::move(w), d.split, left, right, left.owned, right.owned, scratch_.local());
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
        auto& buffers = scratch.children[w.depth + 1];
        split(std::move(w), d.split, left, right, buffers[0], buffers[1], scratch);
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
            const bool sweep = p_.method == KdBuildMethod::sweep ||
                               (p_.method == KdBuildMethod::hybrid && n <= static_cast<std::size_t>(p_.sweep_below));
            if (sweep && !w.events_mode) to_events(w, scratch.converted[w.depth]);
            d.split = w.events_mode ? best_split_sweep(w, sah) : best_split_binned(w, sah);
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

    // Splits `w` (consumed) into the children's Work; their events, if any, go to the two buffers.
    void split(Work&& w, const Split& s, Work& left, Work& right, std::vector<Event>& left_events,
               std::vector<Event>& right_events, Scratch& scratch) const {
        left.cell = right.cell = w.cell;
        left.cell.hi[s.axis] = right.cell.lo[s.axis] = s.pos;
        for (Work* c : {&left, &right}) {
            c->depth = w.depth + 1;
            c->bad_refines = w.bad_refines;
            c->events_mode = w.events_mode;
        }
        if (w.events_mode) split_events(w, s, left, right, left_events, right_events, scratch);
        else split_refs(w, s, left, right);
        w = Work{};
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
        std::vector<Ref>().swap(w.refs);
    }

    // Writes the events of a reference with box `box` on axis `a` to out[0] and maybe out[1];
    // returns how many: 1 for a box flat on the axis, else 2. Both slots are written, branch-free.
    static std::size_t put_events(int a, std::uint32_t tri, const Box3& box, Event* out) {
        const bool planar = box.lo[a] == box.hi[a];
        out[0] = Event(box.lo[a], planar ? kPlanar : kStart, tri);
        out[1] = Event(box.hi[a], kEnd, tri);
        return planar ? 1 : 2;
    }

    // W&H section 4.3: one pass per axis over the sorted events. At each position, the ends and
    // planars there leave the right side, the plane is evaluated with the planars on either side,
    // then the starts and planars join the left side.
    static Split best_split_sweep(const Work& w, const SahCost& sah) {
        SplitSearch search(sah);
        for (int a = 0; a < 3; ++a) {
            const float lo = w.cell.lo[a], hi = w.cell.hi[a];
            if (!(lo < hi)) continue;
            const std::span<const Event> ev = w.events[a];
            std::ptrdiff_t nl = 0, nr = static_cast<std::ptrdiff_t>(w.triangles);
            for (std::size_t i = 0; i < ev.size();) {
                const std::size_t first = i;
                const std::uint32_t at = ev[i].position_class();
                std::ptrdiff_t leaving = 0, planars = 0, joining = 0;  // ends and planars, planars, starts and planars
                do {
                    const std::uint32_t t = ev[i].type();  // kEnd 0, kPlanar 1, kStart 2
                    leaving += (t ^ 2) >> 1;
                    planars += t & 1;
                    joining += (t + 1) >> 1;
                } while (++i < ev.size() && ev[i].position_class() == at);
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
        }
        return search.best();
    }

    // The position of a run of events at equal floats as the float order has it: that of its
    // first event, the one with the smallest key. (The run's events differ only at zero: -0 or +0.)
    static float run_position(std::span<const Event> run) {
        return std::min_element(run.begin(), run.end(), [](Event a, Event b) { return a.key() < b.key(); })->pos();
    }

    // Shevtsov et al. section 3.2: min-max binning over the references' tight bounds.
    Split best_split_binned(const Work& w, const SahCost& sah) const {
        SplitSearch search(sah);
        Box3 tight;
        for (const Ref& r : w.refs) tight.extend(r.box);
        tight = intersection(tight, w.cell);
        const int bins = p_.bins;
        std::vector<std::uint32_t> starts(bins), ends(bins);
        for (int a = 0; a < 3; ++a) {
            const float lo = tight.lo[a], hi = tight.hi[a];
            if (!(lo < hi)) continue;
            const float scale = static_cast<float>(bins) / (hi - lo);
            auto bin = [&](float x) { return std::clamp(static_cast<int>((x - lo) * scale), 0, bins - 1); };
            std::fill(starts.begin(), starts.end(), 0u);
            std::fill(ends.begin(), ends.end(), 0u);
            for (const Ref& r : w.refs) {
                ++starts[bin(r.box.lo[a])];
                ++ends[bin(r.box.hi[a])];
            }
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

    // The parts of a straddling triangle in the two children of `cell`: clipped (perfect splits), or
    // its box cut to each child cell (every ancestor cell contains the child cell, so the cut needs
    // no earlier box).
    std::pair<Box3, Box3> child_boxes(std::uint32_t tri, const Box3& cell, const Split& s) const {
        if (p_.perfect_splits) return clipped_child_bounds(tris_[tri], cell, s.axis, s.pos);
        Box3 lcell = cell, rcell = cell;
        lcell.hi[s.axis] = rcell.lo[s.axis] = s.pos;
        const Box3 b = tris_[tri].bounds();
        return {intersection(b, lcell), intersection(b, rcell)};
    }

    void split_refs(const Work& w, const Split& s, Work& left, Work& right) const {
        const int a = s.axis;
        left.refs.reserve(w.refs.size());
        right.refs.reserve(w.refs.size());
        for (const Ref& r : w.refs) {
            const bool planar_here = r.box.lo[a] == s.pos && r.box.hi[a] == s.pos;
            const bool goes_left = r.box.lo[a] < s.pos || planar_here;
            const bool goes_right = r.box.hi[a] > s.pos;
            if (goes_left && goes_right) {
                const auto [lb, rb] = child_boxes(r.triangle, w.cell, s);
                if (!lb.is_empty()) left.refs.push_back({r.triangle, lb});
                if (!rb.is_empty()) right.refs.push_back({r.triangle, rb});
            } else if (goes_left) {
                left.refs.push_back(r);
            } else {
                right.refs.push_back(r);
            }
        }
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
        std::size_t nl = 0, nr = 0, straddlers = 0;
        for (const Event e : events) {
            const float pos = e.pos();
            const std::uint32_t t = e.triangle();
            const std::size_t where = 1 + std::size_t{pos > s.pos} - std::size_t{pos < s.pos};
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

    // Sorts the few events a split adds to one list. Short lists are sorted by rank (an event's
    // place is the number of smaller events): no branch, unlike the unpredictable loop exits of
    // the insertion sort std::sort uses there.
    static void sort_events(std::span<Event> list) {
        constexpr std::size_t kByRank = 32;
        const std::size_t n = list.size();
        if (n > kByRank) return std::sort(list.begin(), list.end());
        Event unsorted[kByRank];
        std::copy_n(list.begin(), n, unsorted);
        for (std::size_t i = 0; i < n; ++i) {
            std::size_t rank = 0;
            for (std::size_t j = 0; j < n; ++j) rank += unsorted[j] < unsorted[i];
            list[rank] = unsorted[i];
        }
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
