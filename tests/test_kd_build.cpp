// The SAH kd-tree builder against a plain reference builder that lives only here. The reference does
// what kd_build.cpp does in the most direct way: events as (float, key) pairs sorted with std::sort
// and kept sorted with std::inplace_merge (Wald & Havran 2006, section 4), every SAH candidate
// costed with its divisions, straddlers clipped from scratch against each child cell, std::nextafter
// for the outward rounding, a vector per node. The library's fast paths (integer events, branch-free
// loops, screened SAH costs, shared clipping, per-depth buffers) must build the very same bytes: same
// splits, same leaves, same order, for every scene and parameter set here.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "kernel/subtree.hpp"
#include "cellrt/builtin.hpp"
#include "kdtree/kd_tree.hpp"
#include "scenes.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

namespace reference {

using detail::KdBuildMethod;
using detail::KdBuildParams;
using detail::KdNode;
using detail::KdTree;
using detail::Subtree;

enum EventType : std::uint32_t { kEnd = 0, kPlanar = 1, kStart = 2 };

struct Event {
    float pos;
    std::uint32_t key;  // type << 30 | triangle
    EventType type() const { return static_cast<EventType>(key >> 30); }
    std::uint32_t triangle() const { return key & ((1u << 30) - 1); }
    friend bool operator<(const Event& a, const Event& b) { return a.pos < b.pos || (a.pos == b.pos && a.key < b.key); }
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

// Sutherland-Hodgman against the cell's planes x-lo, x-hi, y-lo, ..., z-hi, in double.
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
            auto inside = [&](const P& p) { return side == 0 ? p.c[a] >= plane : p.c[a] <= plane; };
            if (std::all_of(poly, poly + n, inside)) continue;
            int m = 0;
            for (int i = 0; i < n; ++i) {
                const P& cur = poly[i];
                const P& nxt = poly[(i + 1) % n];
                if (inside(cur)) next[m++] = cur;
                if (inside(cur) != inside(nxt)) {
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

struct Split {
    double cost = std::numeric_limits<double>::infinity();
    int axis = -1;
    float pos = 0.f;
    bool planar_left = true;
};

struct Node {
    Box3 cell;
    int depth = 0;
    int bad_refines = 0;
    bool events_mode = false;
    std::vector<Ref> refs;
    std::vector<Event> events[3];
    std::size_t triangles = 0;
    std::size_t size() const { return events_mode ? triangles : refs.size(); }
};

class Builder {
public:
    Builder(std::span<const Triangle> tris, const KdBuildParams& p)
        : tris_(tris), p_(p), depth_limit_(p.depth_limit(tris.size())), side_(tris.size(), 0) {}

    KdTree build() {
        KdTree tree;
        tree.triangle_count = tris_.size();
        Node root;
        for (std::uint32_t i = 0; i < tris_.size(); ++i) {
            const Box3 b = tris_[i].bounds();
            root.cell.extend(b);
            root.refs.push_back({i, b});
        }
        if (tris_.empty()) root.cell = Box3{Vec3(0.f), Vec3(0.f)};
        tree.bounds = root.cell;
        Subtree<KdNode> top;
        top.nodes.resize(1);
        build(std::move(root), top, 0);
        tree.nodes.resize(2);
        detail::flatten(top, 0, tree.nodes, tree.indices, KdNode::kMaxIndex, "kd-tree");
        return tree;
    }

private:
    // SAH probabilities of the children of `cell` split at `pos` on axis `a`.
    std::pair<double, double> probabilities(const Box3& cell, int a, float pos) const {
        const double e[3] = {double(cell.hi.x) - cell.lo.x, double(cell.hi.y) - cell.lo.y,
                             double(cell.hi.z) - cell.lo.z};
        const double b = e[(a + 1) % 3], c = e[(a + 2) % 3];
        const double half_area = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
        const double wl = double(pos) - cell.lo[a], wr = double(cell.hi[a]) - pos;
        return {(b * c + wl * (b + c)) / half_area, (b * c + wr * (b + c)) / half_area};
    }
    double cost(const Box3& cell, int a, float pos, std::size_t nl, std::size_t nr) const {
        const auto [pl, pr] = probabilities(cell, a, pos);
        double c = p_.traversal_cost + p_.intersection_cost * (pl * double(nl) + pr * double(nr));
        if (nl == 0 || nr == 0) c *= 1.0 - p_.empty_bonus;
        return c;
    }

    double build(Node&& w, Subtree<KdNode>& out, std::uint32_t slot) {
        const std::size_t n = w.size();
        const Box3 cell = w.cell;
        Split best;
        bool leaf = true;
        const double e[3] = {double(cell.hi.x) - cell.lo.x, double(cell.hi.y) - cell.lo.y,
                             double(cell.hi.z) - cell.lo.z};
        if (n > static_cast<std::size_t>(p_.leaf_size) && w.depth < depth_limit_ &&
            e[0] * e[1] + e[1] * e[2] + e[2] * e[0] > 0.0) {
            const bool sweep = p_.method == KdBuildMethod::sweep ||
                               (p_.method == KdBuildMethod::hybrid && n <= static_cast<std::size_t>(p_.sweep_below));
            if (sweep && !w.events_mode) to_events(w);
            best = w.events_mode ? sweep_split(w) : binned_split(w);
            if (best.axis >= 0) {
                const double leaf_cost = p_.intersection_cost * static_cast<double>(n);
                leaf = false;
                if (best.cost >= leaf_cost) {
                    if ((best.cost > 4.0 * leaf_cost && n < 16) || w.bad_refines >= p_.max_bad_refines) leaf = true;
                    else ++w.bad_refines;
                }
            }
        }
        if (leaf) {
            std::vector<std::uint32_t> tris;
            if (w.events_mode) {
                for (const Event& ev : w.events[0])
                    if (ev.type() != kEnd) tris.push_back(ev.triangle());
            } else {
                for (const Ref& r : w.refs) tris.push_back(r.triangle);
            }
            return write_leaf(std::move(tris), out, slot);
        }
        Node left, right;
        left.cell = right.cell = cell;
        left.cell.hi[best.axis] = right.cell.lo[best.axis] = best.pos;
        for (Node* c : {&left, &right}) {
            c->depth = w.depth + 1;
            c->bad_refines = w.bad_refines;
            c->events_mode = w.events_mode;
        }
        if (w.events_mode) split_events(w, best, left, right);
        else split_refs(w, best, left, right);
        w = Node{};
        const std::size_t nodes_before = out.nodes.size(), indices_before = out.indices.size();
        const auto pair = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.resize(out.nodes.size() + 2);
        out.nodes[slot] = KdNode::inner(best.axis, best.pos, pair);
        const double left_cost = build(std::move(left), out, pair);
        const double right_cost = build(std::move(right), out, pair + 1);
        const auto [pl, pr] = probabilities(cell, best.axis, best.pos);
        const double subtree_cost = p_.traversal_cost + pl * left_cost + pr * right_cost;
        if (!(p_.retract && subtree_cost >= p_.intersection_cost * static_cast<double>(n))) return subtree_cost;
        std::vector<std::uint32_t> tris(out.indices.begin() + static_cast<std::ptrdiff_t>(indices_before), out.indices.end());
        out.nodes.resize(nodes_before);
        out.indices.resize(indices_before);
        return write_leaf(std::move(tris), out, slot);
    }

    double write_leaf(std::vector<std::uint32_t> tris, Subtree<KdNode>& out, std::uint32_t slot) const {
        std::sort(tris.begin(), tris.end());
        tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
        out.nodes[slot] = KdNode::leaf(static_cast<std::uint32_t>(out.indices.size()), static_cast<std::uint32_t>(tris.size()));
        out.indices.insert(out.indices.end(), tris.begin(), tris.end());
        return p_.intersection_cost * static_cast<double>(tris.size());
    }

    static void to_events(Node& w) {
        for (const Ref& r : w.refs) add_events(r.triangle, r.box, w.events);
        for (auto& list : w.events) std::sort(list.begin(), list.end());
        w.triangles = w.refs.size();
        w.events_mode = true;
        w.refs.clear();
    }

    Split sweep_split(const Node& w) const {
        Split best;
        for (int a = 0; a < 3; ++a) {
            if (!(w.cell.lo[a] < w.cell.hi[a])) continue;
            const std::vector<Event>& ev = w.events[a];
            std::size_t nl = 0, nr = w.triangles;
            for (std::size_t i = 0; i < ev.size();) {
                const float pos = ev[i].pos;
                std::size_t ends = 0, planars = 0, starts = 0;
                while (i < ev.size() && ev[i].pos == pos && ev[i].type() == kEnd) ++ends, ++i;
                while (i < ev.size() && ev[i].pos == pos && ev[i].type() == kPlanar) ++planars, ++i;
                while (i < ev.size() && ev[i].pos == pos && ev[i].type() == kStart) ++starts, ++i;
                nr -= planars + ends;
                if (w.cell.lo[a] < pos && pos < w.cell.hi[a]) {
                    const double left = cost(w.cell, a, pos, nl + planars, nr);
                    const double right = cost(w.cell, a, pos, nl, nr + planars);
                    if (left < best.cost) best = {left, a, pos, true};
                    if (right < best.cost) best = {right, a, pos, false};
                }
                nl += starts + planars;
            }
        }
        return best;
    }

    Split binned_split(const Node& w) const {
        Split best;
        Box3 tight;
        for (const Ref& r : w.refs) tight.extend(r.box);
        tight = intersection(tight, w.cell);
        const int bins = p_.bins;
        for (int a = 0; a < 3; ++a) {
            const float lo = tight.lo[a], hi = tight.hi[a];
            if (!(lo < hi)) continue;
            const float scale = static_cast<float>(bins) / (hi - lo);
            auto bin = [&](float x) { return std::clamp(static_cast<int>((x - lo) * scale), 0, bins - 1); };
            std::vector<std::size_t> starts(bins), ends(bins);
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
                const double c = cost(w.cell, a, pos, nl, nr);
                if (c < best.cost) best = {c, a, pos, true};
            }
        }
        return best;
    }

    Box3 child_box(std::uint32_t tri, const Box3& cell) const {
        return p_.perfect_splits ? clipped_bounds(tris_[tri], cell) : intersection(tris_[tri].bounds(), cell);
    }

    void split_refs(const Node& w, const Split& s, Node& left, Node& right) const {
        const int a = s.axis;
        for (const Ref& r : w.refs) {
            const bool goes_left = r.box.lo[a] < s.pos || (r.box.lo[a] == s.pos && r.box.hi[a] == s.pos);
            const bool goes_right = r.box.hi[a] > s.pos;
            if (goes_left && goes_right) {
                const Box3 lb = child_box(r.triangle, left.cell), rb = child_box(r.triangle, right.cell);
                if (!lb.is_empty()) left.refs.push_back({r.triangle, lb});
                if (!rb.is_empty()) right.refs.push_back({r.triangle, rb});
            } else {
                (goes_left ? left : right).refs.push_back(r);
            }
        }
    }

    // side_: 0 both, 1 left, 2 right
    void split_events(const Node& w, const Split& s, Node& left, Node& right) {
        for (const Event& e : w.events[s.axis]) {
            const std::uint32_t t = e.triangle();
            if (e.type() == kEnd && e.pos <= s.pos) side_[t] = 1;
            if (e.type() == kStart && e.pos >= s.pos) side_[t] = 2;
            if (e.type() == kPlanar) side_[t] = (e.pos < s.pos || (e.pos == s.pos && s.planar_left)) ? 1 : 2;
        }
        std::vector<std::uint32_t> straddling;
        std::size_t nl = 0, nr = 0;
        for (const Event& e : w.events[0]) {
            if (e.type() == kEnd) continue;
            const std::uint8_t sd = side_[e.triangle()];
            if (sd == 0) straddling.push_back(e.triangle());
            nl += sd == 1;
            nr += sd == 2;
        }
        for (int k = 0; k < 3; ++k)
            for (const Event& e : w.events[k]) {
                if (side_[e.triangle()] == 1) left.events[k].push_back(e);
                if (side_[e.triangle()] == 2) right.events[k].push_back(e);
            }
        for (const Event& e : w.events[s.axis]) side_[e.triangle()] = 0;
        std::vector<Event> new_left[3], new_right[3];
        for (const std::uint32_t t : straddling) {
            const Box3 lb = child_box(t, left.cell), rb = child_box(t, right.cell);
            if (!lb.is_empty()) add_events(t, lb, new_left), ++nl;
            if (!rb.is_empty()) add_events(t, rb, new_right), ++nr;
        }
        for (int k = 0; k < 3; ++k) {
            merge_into(left.events[k], new_left[k]);
            merge_into(right.events[k], new_right[k]);
        }
        left.triangles = nl;
        right.triangles = nr;
    }

    static void merge_into(std::vector<Event>& sorted, std::vector<Event>& extra) {
        std::sort(extra.begin(), extra.end());
        const auto mid = static_cast<std::ptrdiff_t>(sorted.size());
        sorted.insert(sorted.end(), extra.begin(), extra.end());
        std::inplace_merge(sorted.begin(), sorted.begin() + mid, sorted.end());
    }

    std::span<const Triangle> tris_;
    const KdBuildParams& p_;
    int depth_limit_;
    std::vector<std::uint8_t> side_;
};

KdTree build(std::span<const Triangle> tris, const KdBuildParams& p) { return Builder(tris, p).build(); }

}  // namespace reference

struct NamedParams {
    std::string name;
    detail::KdBuildParams params;
};

std::vector<NamedParams> parameter_sets() {
    std::vector<NamedParams> out;
    auto add = [&](std::string name, auto set) {
        detail::KdBuildParams p;
        p.threads = 1;
        p.clip_ratio = 0.0;  // the reference clips every straddler
        set(p);
        out.push_back({std::move(name), p});
    };
    add("default", [](auto&) {});
    add("sweep", [](auto& p) { p.method = detail::KdBuildMethod::sweep; });
    add("binned", [](auto& p) { p.method = detail::KdBuildMethod::binned; });
    add("binned, 16 bins", [](auto& p) { p.method = detail::KdBuildMethod::binned; p.bins = 16; });
    add("sweep below 64", [](auto& p) { p.sweep_below = 64; });
    add("no perfect splits", [](auto& p) { p.perfect_splits = false; });
    add("leaf size 1, no retraction", [](auto& p) { p.leaf_size = 1; p.retract = false; });
    add("costs", [](auto& p) { p.empty_bonus = 0.9; p.traversal_cost = 1.0; p.intersection_cost = 80.0; });
    add("no bonus, no bad refinements", [](auto& p) { p.empty_bonus = 0.0; p.max_bad_refines = 0; });
    add("three bad refinements (Mitsuba)", [](auto& p) { p.max_bad_refines = 3; });
    add("depth 6", [](auto& p) { p.max_depth = 6; });
    return out;
}

void expect_same_tree(const detail::KdTree& expected, const detail::KdTree& actual, const std::string& what) {
    EXPECT_EQ(expected.bounds, actual.bounds) << what;
    EXPECT_EQ(expected.triangle_count, actual.triangle_count) << what;
    ASSERT_EQ(expected.nodes.size(), actual.nodes.size()) << what;
    EXPECT_EQ(expected.indices, actual.indices) << what;
    // Bytes, so that a split at -0 differs from one at +0.
    EXPECT_EQ(std::memcmp(expected.nodes.data(), actual.nodes.data(), expected.nodes.size() * sizeof(detail::KdNode)), 0)
        << what;
}

void expect_as_reference(const std::string& scene, std::span<const Triangle> tris) {
    for (const NamedParams& np : parameter_sets())
        expect_same_tree(reference::build(tris, np.params), detail::build_kdtree(tris, np.params), scene + ", " + np.name);
}

TEST(KdBuild, SameTreeAsTheReferenceOnBuiltinScenes) {
    for (const char* spec : {"builtin:spheres?tris=3000", "builtin:city?tris=8000", "builtin:forest?tris=8000"})
        expect_as_reference(spec, test::cached_scene(spec).triangles);
}

TEST(KdBuild, SameTreeAsTheReferenceOnTheTeapot) {
    CELLRT_REQUIRE_SHARED_SCENE(path, "teapot");
    expect_as_reference("teapot", test::cached_scene(path).triangles);
}

TEST(KdBuild, SameTreeAsTheReferenceOnDegenerateScenes) {
    for (const auto& [name, tris] : test::degenerate_scenes()) expect_as_reference(name, tris);
}

// Two slabs of triangles meeting at x = 0, some straddling, some lying in the plane, with -0 and +0
// mixed: the float order sees one position there, ordered by type and triangle, and the split takes
// the sign of its first event. The library's integer events order -0 before +0 and must still agree.
std::vector<Triangle> signed_zero_scene(bool left_at_negative_zero) {
    const float left_edge = left_at_negative_zero ? -0.f : 0.f, right_edge = left_at_negative_zero ? 0.f : -0.f;
    std::vector<Triangle> tris;
    std::uint32_t state = 99;
    auto next = [&] { return float((state = state * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
    for (int i = 0; i < 400; ++i) {
        const float y = next() * 8.f, z = next() * 8.f, w = 0.5f + next();
        tris.push_back({{-w, y, z}, {left_edge, y + 0.3f, z}, {left_edge, y, z + 0.3f}});
        tris.push_back({{right_edge, y, z}, {w, y + 0.3f, z}, {right_edge, y, z + 0.3f}});
        if (i % 10 == 0) tris.push_back({{i % 20 ? -0.f : 0.f, y, z}, {0.f, y + 0.4f, z}, {-0.f, y, z + 0.4f}});
        if (i % 25 == 0) tris.push_back({{-w, y, z}, {w, y + 0.2f, z}, {w, y, z + 0.2f}});
    }
    return tris;
}

TEST(KdBuild, SameTreeAsTheReferenceAtSignedZeros) {
    bool split_at_negative_zero = false;
    for (const bool left_at_negative_zero : {true, false}) {
        const std::vector<Triangle> tris = signed_zero_scene(left_at_negative_zero);
        expect_as_reference(left_at_negative_zero ? "-0 | +0" : "+0 | -0", tris);
        for (const detail::KdNode& n : detail::build_kdtree(tris, detail::KdBuildParams{}).nodes)
            split_at_negative_zero |= !n.is_leaf() && std::bit_cast<std::uint32_t>(n.split()) == 0x80000000u;
    }
    EXPECT_TRUE(split_at_negative_zero) << "the scenes should produce a split at -0";
}

// The parallel top splits nodes into tasks with buffers of their own, and below it every thread
// reuses its per-depth buffers: neither may change the tree.
TEST(KdBuild, SameTreeAtAnyThreadCountForEveryMethod) {
    const std::vector<Triangle>& tris = test::cached_scene("builtin:city?tris=20000").triangles;
    std::vector<NamedParams> sets = parameter_sets();
    sets.push_back({"library defaults", detail::KdBuildParams{}});
    sets.back().params.threads = 1;
    for (NamedParams np : sets) {
        const detail::KdTree one = detail::build_kdtree(tris, np.params);
        for (const unsigned threads : {2u, 0u}) {
            np.params.threads = threads;
            expect_same_tree(one, detail::build_kdtree(tris, np.params), np.name + ", " + std::to_string(threads) + " threads");
        }
    }
}

}  // namespace
}  // namespace cellrt
