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
// Parallelism: the two children of a large node are built as separate tasks, each into its own node
// array; a final pass lays the pieces out depth-first. The layout depends only on the tree, never on
// which thread built what, so the bytes are the same at any thread count.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "cellrt/error.hpp"
#include "accel/subtree.hpp"
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

struct Event {
    float pos;
    std::uint32_t key;  // type << 30 | triangle: ordering by key orders by type, then triangle

    EventType type() const { return static_cast<EventType>(key >> 30); }
    std::uint32_t triangle() const { return key & kTriangleMask; }
    friend bool operator<(const Event& a, const Event& b) { return a.pos < b.pos || (a.pos == b.pos && a.key < b.key); }
};

struct EventLists {
    std::vector<Event> axis[3];
    std::size_t triangles = 0;
};

struct Ref {
    std::uint32_t triangle;
    Box3 box;
};

void add_events(std::uint32_t tri, const Box3& box, std::vector<Event> (&out)[3]) {
    for (int a = 0; a < 3; ++a) {
        if (box.lo[a] == box.hi[a]) {
            out[a].push_back({box.lo[a], (kPlanar << 30) | tri});
        } else {
            out[a].push_back({box.lo[a], (kStart << 30) | tri});
            out[a].push_back({box.hi[a], (kEnd << 30) | tri});
        }
    }
}

// Rounds a double down / up to the next float, then one more float step outward: the clipped
// polygon is computed in double, and this keeps its float box conservative.
float float_below(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return std::nextafter(f, -std::numeric_limits<float>::infinity());
}
float float_above(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return std::nextafter(f, std::numeric_limits<float>::infinity());
}

// Bounds of the part of `tri` inside `cell` (Sutherland-Hodgman clipping against the cell's six
// planes, in double precision), rounded outward and cut to the cell. Empty when they do not meet.
Box3 clipped_bounds(const Triangle& tri, const Box3& cell) {
    struct P {
        double c[3];
    };
    P poly[9], next[9];
    int n = 3;
    const Vec3 v[3] = {tri.v0, tri.v1, tri.v2};
    for (int i = 0; i < 3; ++i) poly[i] = {{v[i].x, v[i].y, v[i].z}};
    for (int a = 0; a < 3 && n > 0; ++a) {
        for (int side = 0; side < 2 && n > 0; ++side) {
            const double plane = side == 0 ? cell.lo[a] : cell.hi[a];
            // inside: c >= plane for the low plane, c <= plane for the high one
            auto inside = [&](const P& p) { return side == 0 ? p.c[a] >= plane : p.c[a] <= plane; };
            bool all_in = true;
            for (int i = 0; i < n; ++i) all_in = all_in && inside(poly[i]);
            if (all_in) continue;
            int m = 0;
            for (int i = 0; i < n; ++i) {
                const P& cur = poly[i];
                const P& nxt = poly[(i + 1) % n];
                const bool cin = inside(cur), nin = inside(nxt);
                if (cin) next[m++] = cur;
                if (cin != nin) {
                    const double s = (plane - cur.c[a]) / (nxt.c[a] - cur.c[a]);
                    P x;
                    for (int k = 0; k < 3; ++k) x.c[k] = cur.c[k] + s * (nxt.c[k] - cur.c[k]);
                    x.c[a] = plane;
                    next[m++] = x;
                }
            }
            n = m;
            std::copy(next, next + n, poly);
        }
    }
    if (n == 0) return Box3::empty();
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = hi[k] = poly[0].c[k];
    for (int i = 1; i < n; ++i)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], poly[i].c[k]), hi[k] = std::max(hi[k], poly[i].c[k]);
    Box3 b;
    for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::max(float_below(lo[k]), cell.lo[k]);
        b.hi[k] = std::min(float_above(hi[k]), cell.hi[k]);
    }
    return b;
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
    }
    bool splittable() const { return half_area_ > 0.0; }
    double leaf(std::size_t n) const { return p_.intersection_cost * static_cast<double>(n); }
    // Probabilities that a ray through the cell passes through the left and the right child.
    std::pair<double, double> probabilities(int a, float pos) const {
        const double wl = double(pos) - cell_.lo[a], wr = double(cell_.hi[a]) - pos;
        return {(constant_[a] + wl * linear_[a]) / half_area_, (constant_[a] + wr * linear_[a]) / half_area_};
    }
    double split(int a, float pos, std::size_t nl, std::size_t nr) const {
        const auto [pl, pr] = probabilities(a, pos);
        double cost = p_.traversal_cost + p_.intersection_cost * (pl * double(nl) + pr * double(nr));
        if (nl == 0 || nr == 0) cost *= 1.0 - p_.empty_bonus;
        return cost;
    }

private:
    Box3 cell_;
    const KdBuildParams& p_;
    double constant_[3], linear_[3], half_area_;
};

struct Split {
    double cost = std::numeric_limits<double>::infinity();
    int axis = -1;
    float pos = 0.f;
    bool planar_left = true;  // where triangles lying in the plane go
};

// What the builder knows about one node: its cell, its path, and its references either as boxes
// (binning) or as sorted event lists (sweep).
struct Work {
    Box3 cell;
    int depth = 0;
    int bad_refines = 0;
    bool events_mode = false;
    std::vector<Ref> refs;
    EventLists events;

    std::size_t size() const { return events_mode ? events.triangles : refs.size(); }
};

enum class Side : std::uint8_t { both, left, right };

class KdBuilder {
public:
    KdBuilder(std::span<const Triangle> tris, const KdBuildParams& p)
        : tris_(tris), p_(p), depth_limit_(p.depth_limit(tris.size())),
          sides_([n = tris.size()] { return std::vector<Side>(n, Side::both); }) {}

    KdTree build() {
        KdTree tree;
        tree.triangle_count = tris_.size();
        Work root;
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
        std::size_t size = 0;                  // references in the node
        std::vector<std::uint32_t> triangles;  // leaf
        Work left, right;                      // split
    };

    // Builds the subtree of `w`; large nodes split into two tasks. Its cost (the SAH estimate of the
    // work for a ray through the cell) is kept for retraction.
    std::unique_ptr<Subtree<KdNode>> subtree(Work&& w) {
        auto out = std::make_unique<Subtree<KdNode>>();
        if (w.size() < kParallelMin || p_.threads == 1) {
            out->nodes.resize(1);
            out->cost = sequential(std::move(w), *out, 0);
            return out;
        }
        const Box3 cell = w.cell;
        Decision d = decide(std::move(w));
        if (d.leaf) {
            out->nodes = {KdNode::leaf(0, static_cast<std::uint32_t>(d.triangles.size()))};
            out->cost = p_.intersection_cost * static_cast<double>(d.triangles.size());
            out->indices = std::move(d.triangles);
            return out;
        }
        out->nodes = {KdNode::inner(d.split.axis, d.split.pos, 0)};
        tbb::task_group group;
        group.run([&] { out->left = subtree(std::move(d.left)); });
        out->right = subtree(std::move(d.right));
        group.wait();
        out->cost = split_cost(cell, d.split, out->left->cost, out->right->cost);
        if (retract(out->cost, d.size)) {
            std::vector<std::uint32_t> tris;
            gather(*out, tris);
            *out = Subtree<KdNode>{};
            out->nodes.resize(1);
            out->cost = leaf(std::move(tris), *out, 0);
        }
        return out;
    }

    double sequential(Work&& w, Subtree<KdNode>& out, std::uint32_t slot) {
        const Box3 cell = w.cell;
        Decision d = decide(std::move(w));
        if (d.leaf) return leaf(std::move(d.triangles), out, slot);
        const std::size_t nodes_before = out.nodes.size(), indices_before = out.indices.size();
        const auto pair = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.resize(out.nodes.size() + 2);
        out.nodes[slot] = KdNode::inner(d.split.axis, d.split.pos, pair);
        Work right = std::move(d.right);
        const double left_cost = sequential(std::move(d.left), out, pair);
        const double right_cost = sequential(std::move(right), out, pair + 1);
        const double cost = split_cost(cell, d.split, left_cost, right_cost);
        if (!retract(cost, d.size)) return cost;
        std::vector<std::uint32_t> tris(out.indices.begin() + static_cast<std::ptrdiff_t>(indices_before), out.indices.end());
        out.nodes.resize(nodes_before);
        out.indices.resize(indices_before);
        return leaf(std::move(tris), out, slot);
    }

    // Writes a leaf with the sorted, distinct triangles of `tris`; returns its cost.
    double leaf(std::vector<std::uint32_t> tris, Subtree<KdNode>& out, std::uint32_t slot) const {
        std::sort(tris.begin(), tris.end());
        tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
        out.nodes[slot] = KdNode::leaf(static_cast<std::uint32_t>(out.indices.size()), static_cast<std::uint32_t>(tris.size()));
        out.indices.insert(out.indices.end(), tris.begin(), tris.end());
        return p_.intersection_cost * static_cast<double>(tris.size());
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

    // Leaf or split, and the children's references (W&H section 5 termination, with Mitsuba's
    // bad-refinement rule: a split costing more than a leaf is tolerated a few times on a path,
    // since a later split may pay for it).
    Decision decide(Work&& w) {
        Decision d;
        const std::size_t n = w.size();
        d.size = n;
        const SahCost sah(w.cell, p_);
        if (n > static_cast<std::size_t>(p_.leaf_size) && w.depth < depth_limit_ && sah.splittable()) {
            const bool sweep = p_.method == KdBuildMethod::sweep ||
                               (p_.method == KdBuildMethod::hybrid && n <= static_cast<std::size_t>(p_.sweep_below));
            if (sweep && !w.events_mode) to_events(w);
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
        if (d.leaf) {
            d.triangles = leaf_triangles(w);
            return d;
        }
        Box3 lcell = w.cell, rcell = w.cell;
        lcell.hi[d.split.axis] = d.split.pos;
        rcell.lo[d.split.axis] = d.split.pos;
        for (Work* c : {&d.left, &d.right}) {
            c->depth = w.depth + 1;
            c->bad_refines = w.bad_refines;
            c->events_mode = w.events_mode;
        }
        d.left.cell = lcell;
        d.right.cell = rcell;
        if (w.events_mode) split_events(w, d.split, d.left, d.right);
        else split_refs(w, d.split, d.left, d.right);
        return d;
    }

    static std::vector<std::uint32_t> leaf_triangles(const Work& w) {
        std::vector<std::uint32_t> out;
        out.reserve(w.size());
        if (w.events_mode) {
            for (const Event& e : w.events.axis[0])
                if (e.type() != kEnd) out.push_back(e.triangle());
        } else {
            for (const Ref& r : w.refs) out.push_back(r.triangle);
        }
        std::sort(out.begin(), out.end());
        return out;
    }

    static void to_events(Work& w) {
        for (auto& list : w.events.axis) list.reserve(2 * w.refs.size());
        for (const Ref& r : w.refs) add_events(r.triangle, r.box, w.events.axis);
        for (auto& list : w.events.axis) std::sort(list.begin(), list.end());
        w.events.triangles = w.refs.size();
        w.events_mode = true;
        std::vector<Ref>().swap(w.refs);
    }

    // W&H section 4.3: one pass per axis over the sorted events. At each position, the ends and
    // planars there leave the right side, the plane is evaluated with the planars on either side,
    // then the starts and planars join the left side.
    static Split best_split_sweep(const Work& w, const SahCost& sah) {
        Split best;
        const std::size_t n = w.events.triangles;
        for (int a = 0; a < 3; ++a) {
            if (!(w.cell.lo[a] < w.cell.hi[a])) continue;
            const std::vector<Event>& ev = w.events.axis[a];
            std::size_t nl = 0, nr = n;
            for (std::size_t i = 0; i < ev.size();) {
                const float pos = ev[i].pos;
                std::size_t ends = 0, planars = 0, starts = 0;
                while (i < ev.size() && ev[i].pos == pos && ev[i].type() == kEnd) ++ends, ++i;
                while (i < ev.size() && ev[i].pos == pos && ev[i].type() == kPlanar) ++planars, ++i;
                while (i < ev.size() && ev[i].pos == pos && ev[i].type() == kStart) ++starts, ++i;
                nr -= planars + ends;
                if (w.cell.lo[a] < pos && pos < w.cell.hi[a]) {
                    const double left = sah.split(a, pos, nl + planars, nr);
                    const double right = sah.split(a, pos, nl, nr + planars);
                    if (left < best.cost) best = {left, a, pos, true};
                    if (right < best.cost) best = {right, a, pos, false};
                }
                nl += starts + planars;
            }
        }
        return best;
    }

    // Shevtsov et al. section 3.2: min-max binning over the references' tight bounds.
    Split best_split_binned(const Work& w, const SahCost& sah) const {
        Split best;
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
            std::size_t nl = 0, nr = w.refs.size();
            for (int i = 1; i < bins; ++i) {
                nl += starts[i - 1];
                nr -= ends[i - 1];
                const float pos = lo + (hi - lo) * (static_cast<float>(i) / static_cast<float>(bins));
                if (!(w.cell.lo[a] < pos && pos < w.cell.hi[a])) continue;
                const double cost = sah.split(a, pos, nl, nr);
                if (cost < best.cost) best = {cost, a, pos, true};
            }
        }
        return best;
    }

    // The part of a straddling triangle in a child cell: clipped (perfect splits), or its box cut to
    // the cell (every ancestor cell contains the child cell, so the cut needs no earlier box).
    Box3 child_box(std::uint32_t tri, const Box3& cell) const {
        return p_.perfect_splits ? clipped_bounds(tris_[tri], cell) : intersection(tris_[tri].bounds(), cell);
    }

    void split_refs(Work& w, const Split& s, Work& left, Work& right) const {
        const int a = s.axis;
        for (const Ref& r : w.refs) {
            const bool planar_here = r.box.lo[a] == s.pos && r.box.hi[a] == s.pos;
            const bool goes_left = r.box.lo[a] < s.pos || planar_here;
            const bool goes_right = r.box.hi[a] > s.pos;
            if (goes_left && goes_right) {
                const Box3 lb = child_box(r.triangle, left.cell);
                const Box3 rb = child_box(r.triangle, right.cell);
                if (!lb.is_empty()) left.refs.push_back({r.triangle, lb});
                if (!rb.is_empty()) right.refs.push_back({r.triangle, rb});
            } else if (goes_left) {
                left.refs.push_back(r);
            } else {
                right.refs.push_back(r);
            }
        }
        std::vector<Ref>().swap(w.refs);
    }

    // W&H section 4.4: classify triangles by the split axis's events, copy the one-sided triangles'
    // events in order, clip the straddlers to both children, sort only their new events and merge.
    void split_events(Work& w, const Split& s, Work& left, Work& right) {
        std::vector<Side>& side = sides_.local();
        const int a = s.axis;
        for (const Event& e : w.events.axis[a]) {
            const std::uint32_t t = e.triangle();
            switch (e.type()) {
                case kEnd:
                    if (e.pos <= s.pos) side[t] = Side::left;
                    break;
                case kStart:
                    if (e.pos >= s.pos) side[t] = Side::right;
                    break;
                case kPlanar:
                    if (e.pos < s.pos || (e.pos == s.pos && s.planar_left)) side[t] = Side::left;
                    else side[t] = Side::right;
                    break;
            }
        }
        std::vector<std::uint32_t> straddling;
        std::vector<std::uint32_t> in_node;
        in_node.reserve(w.events.triangles);
        std::size_t nl = 0, nr = 0;
        for (const Event& e : w.events.axis[0]) {
            if (e.type() == kEnd) continue;
            in_node.push_back(e.triangle());
            const Side sd = side[e.triangle()];
            if (sd == Side::both) straddling.push_back(e.triangle());
            else if (sd == Side::left) ++nl;
            else ++nr;
        }
        for (int k = 0; k < 3; ++k) {
            left.events.axis[k].reserve(w.events.axis[k].size());
            right.events.axis[k].reserve(w.events.axis[k].size());
            for (const Event& e : w.events.axis[k]) {
                const Side sd = side[e.triangle()];
                if (sd == Side::left) left.events.axis[k].push_back(e);
                else if (sd == Side::right) right.events.axis[k].push_back(e);
            }
            std::vector<Event>().swap(w.events.axis[k]);
        }
        for (const std::uint32_t t : in_node) side[t] = Side::both;  // the scratch is per thread, reused
        std::vector<Event> new_left[3], new_right[3];
        for (const std::uint32_t t : straddling) {
            const Box3 lb = child_box(t, left.cell);
            const Box3 rb = child_box(t, right.cell);
            if (!lb.is_empty()) add_events(t, lb, new_left), ++nl;
            if (!rb.is_empty()) add_events(t, rb, new_right), ++nr;
        }
        for (int k = 0; k < 3; ++k) {
            merge_into(left.events.axis[k], new_left[k]);
            merge_into(right.events.axis[k], new_right[k]);
        }
        left.events.triangles = nl;
        right.events.triangles = nr;
    }

    static void merge_into(std::vector<Event>& sorted, std::vector<Event>& extra) {
        if (extra.empty()) return;
        std::sort(extra.begin(), extra.end());
        const auto mid = static_cast<std::ptrdiff_t>(sorted.size());
        sorted.insert(sorted.end(), extra.begin(), extra.end());
        std::inplace_merge(sorted.begin(), sorted.begin() + mid, sorted.end());
    }

    std::span<const Triangle> tris_;
    const KdBuildParams& p_;
    int depth_limit_;
    tbb::enumerable_thread_specific<std::vector<Side>> sides_;
};

}  // namespace

KdTree build_kdtree(std::span<const Triangle> triangles, const KdBuildParams& params) {
    if (triangles.size() > kTriangleMask) throw Error("kd-tree: at most 2^30 triangles are supported");
    return KdBuilder(triangles, params).build();
}

}  // namespace cellrt::detail
