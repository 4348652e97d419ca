// The wide BVH beyond the checks every structure faces (test_structures.cpp): build variants stay
// exact, the tree's invariants (without spatial splits every triangle in exactly one leaf and every
// box the exact bounds of what lies below it; with them every triangle covered within the budget;
// leaves no larger than asked), the same tree from the same input, rays along its own box faces,
// and an empty scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "accel/routed_accelerator.hpp"
#include "bvh/bvh_accel.hpp"
#include "bvh/bvh_build.hpp"
#include "bvh/split_reference.hpp"
#include "simd/isa.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/workload.hpp"
#include "cellrt/error.hpp"
#include "ray_suite.hpp"
#include "scenes.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

using detail::BvhBuildOptions;
using detail::BvhNode;
using detail::BvhTree;

AccelConfig bvh(std::map<std::string, std::string> params = {}) {
    AccelConfig c{"bvh"};
    c.params = std::move(params);
    return c;
}

TEST(Bvh, BuildVariantsMatchBruteForce) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const test::ReferenceAnswers& ref = test::cached_reference("builtin:spheres?tris=3000", scene.triangles);
    for (const std::map<std::string, std::string>& params : std::vector<std::map<std::string, std::string>>{
             {{"max_leaf", "1"}}, {{"max_leaf", "3"}}, {{"bins", "2"}}, {{"bins", "256"}},
             {{"traversal_cost", "1000"}}, {{"intersection_cost", "1000"}}, {{"split_budget", "0"}},
             {{"split_budget", "4"}, {"max_leaf", "1"}}}) {
        std::string what = "bvh";
        for (const auto& [k, v] : params) what += " " + k + "=" + v;
        test::expect_matches(*make_accelerator(scene.triangles, bvh(params)), ref, what);
    }
}

// Walks the wide tree. Every leaf's lanes name triangles whose vertices the lanes hold. Without
// spatial splits each triangle lies in exactly one leaf and every child box is exactly the bounds of
// the triangles below it. With them a triangle may lie in several leaves, cut by the planes between
// them: then a leaf's box lies within its triangles' bounds, an inner child's box holds its
// children's, and each vertex of a triangle lies in the box of one of the leaves that hold it. A
// node's children come by decreasing box area (any-hit traversals take the first one met).
void check_tree(const BvhTree& tree, std::span<const Triangle> tris, int max_leaf, bool spatial = false) {
    std::vector<int> seen(tris.size(), 0);
    std::vector<std::vector<Box3>> leaf_boxes(tris.size());
    // Returns the bounds of the triangles below `word`; `stored` is the box its parent keeps for it.
    std::function<Box3(std::uint32_t, const Box3&)> walk = [&](std::uint32_t word, const Box3& stored) -> Box3 {
        Box3 bounds;
        if (BvhNode::is_leaf(word)) {
            const detail::BvhLeaf& leaf = tree.leaves[BvhNode::leaf_index(word)];
            const std::uint32_t n = BvhNode::leaf_count(word);
            EXPECT_LE(n, static_cast<std::uint32_t>(max_leaf));
            for (std::uint32_t lane = 0; lane < detail::kBvhWidth; ++lane) {
                if (lane >= n) {
                    EXPECT_EQ(leaf.prim[lane], kNoHit);
                    continue;
                }
                const std::uint32_t p = leaf.prim[lane];
                EXPECT_LT(p, tris.size());
                if (p >= tris.size()) continue;
                ++seen[p];
                leaf_boxes[p].push_back(stored);
                const Vec3* v[3] = {&tris[p].v0, &tris[p].v1, &tris[p].v2};
                for (int k = 0; k < 3; ++k)
                    for (int a = 0; a < 3; ++a) EXPECT_EQ(leaf.v[k][a][lane], (*v[k])[static_cast<std::size_t>(a)]);
                bounds.extend(tris[p].bounds());
            }
            return bounds;
        }
        const BvhNode& node = tree.nodes[word];
        Box3 children;
        float previous_area = kInfinity;
        for (int k = 0; k < detail::kBvhWidth; ++k) {
            if (node.child[k] == BvhNode::kEmptyChild) {
                EXPECT_GT(node.lo[0][k], node.hi[0][k]) << "an empty slot's box is empty";
                continue;
            }
            Box3 box;
            for (int a = 0; a < 3; ++a) box.lo[a] = node.lo[a][k], box.hi[a] = node.hi[a][k];
            EXPECT_LE(box.area(), previous_area) << "children not by decreasing box area";
            previous_area = box.area();
            const Box3 child = walk(node.child[k], box);
            if (spatial) {
                EXPECT_EQ(intersection(box, child), box) << "a box beyond its triangles' bounds";
            } else {
                EXPECT_EQ(box, child);
            }
            bounds.extend(child);
            children.extend(box);
        }
        if (spatial) {
            EXPECT_EQ(intersection(stored, children), children) << "children beyond their parent's box";
        }
        return bounds;
    };
    const Box3 root = walk(0, tree.bounds);
    EXPECT_EQ(root, tree.bounds);
    std::size_t references = 0;
    for (std::size_t i = 0; i < tris.size(); ++i) {
        references += static_cast<std::size_t>(seen[i]);
        if (!spatial) {
            EXPECT_EQ(seen[i], 1) << "triangle " << i;
            continue;
        }
        EXPECT_GE(seen[i], 1) << "triangle " << i;
        for (const Vec3* v : {&tris[i].v0, &tris[i].v1, &tris[i].v2})
            EXPECT_TRUE(std::any_of(leaf_boxes[i].begin(), leaf_boxes[i].end(), [&](const Box3& b) { return b.contains(*v); }))
                << "a vertex of triangle " << i << " outside every leaf that holds it";
    }
    EXPECT_EQ(references, tree.references);
}

BvhBuildOptions without_spatial_splits(int max_leaf = 8) {
    BvhBuildOptions o;
    o.max_leaf = max_leaf;
    o.split_budget = 0.0;
    return o;
}

TEST(Bvh, EveryTriangleInOneLeafAndEveryBoxExact) {
    for (const char* name : {"builtin:spheres?tris=3000", "builtin:city?tris=5000", "builtin:forest?tris=5000"}) {
        const Scene& scene = test::cached_scene(name);
        for (int max_leaf : {1, 5, 8}) {
            SCOPED_TRACE(std::string(name) + " max_leaf " + std::to_string(max_leaf));
            check_tree(detail::build_bvh(scene.triangles, without_spatial_splits(max_leaf)), scene.triangles, max_leaf);
        }
    }
}

// A linear congruential generator's numbers in [0, 1): 24 bits, so exact in float and double alike.
struct Lcg {
    std::uint32_t state;
    float next() { return float((state = state * 1664525u + 1013904223u) >> 8) / float(1 << 24); }
};

// Long strips on a plane tilted against every axis, over small triangles scattered around it: the
// strips' boxes overlap wherever objects split them, which is where spatial splits pay (Stich et al.
// 2009, figure 1).
std::vector<Triangle> tilted_strips() {
    std::vector<Triangle> tris;
    const auto lift = [](Vec3 p) { return Vec3{p.x, p.y, 0.3f * p.x + 0.1f * p.y}; };
    for (int i = 0; i < 200; ++i) {
        const float o = static_cast<float>(i) * 0.05f;
        const Vec3 a{o, -o, 0.f}, b{o + 10.f, 10.f - o, 0.f}, c{o + 0.05f, -o, 0.f}, d{o + 10.05f, 10.f - o, 0.f};
        tris.push_back({lift(a), lift(b), lift(c)});
        tris.push_back({lift(c), lift(b), lift(d)});
    }
    Lcg rng{7};
    const auto next = [&] { return rng.next(); };
    for (int i = 0; i < 1600; ++i) {
        const Vec3 p{next() * 10, next() * 10 - 5, next() * 5};
        tris.push_back({p, p + Vec3{0.1f, 0.f, 0.f}, p + Vec3{0.f, 0.1f, 0.05f}});
    }
    return tris;
}

// Long thin triangles in random directions through one cube (grass, hair, struts): every node's
// region is crossed by most of its triangles, so a spatial split duplicates nearly all of them.
std::vector<Triangle> crossing_slivers(int count) {
    std::vector<Triangle> tris;
    Lcg rng{7};
    const auto next = [&] { return rng.next(); };
    for (int i = 0; i < count; ++i) {
        const Vec3 p{next() * 10, next() * 10, next() * 10}, q{next() * 10, next() * 10, next() * 10};
        const Vec3 w{next() * 0.05f, next() * 0.05f, next() * 0.05f};
        tris.push_back({p, q, p + w});
    }
    return tris;
}

// Spatial splits keep every triangle covered, stay within the budget and give brute force's answers
// for every budget, traversal and leaf size; where they pay, the tree's SAH cost falls. (The SAH is
// greedy: on the slivers, duplicating nearly every triangle into one-triangle leaves costs more in
// the end than each split's estimate said, which is why the cost is asserted on the strips alone.)
TEST(Bvh, SpatialSplitsCoverEveryTriangleWithinTheBudget) {
    for (const auto& [name, tris] : {std::pair{"tilted strips", tilted_strips()}, std::pair{"slivers", crossing_slivers(2000)}}) {
        const test::ReferenceAnswers ref = test::compute_reference(tris, test::RaySuite(tris, test::small_suite()).rays());
        for (const double budget : {0.1, 0.5, 4.0})
            for (const int max_leaf : {1, 8}) {
                BvhBuildOptions o;
                o.split_budget = budget;
                o.max_leaf = max_leaf;
                const BvhTree tree = detail::build_bvh(tris, o);
                const std::string what =
                    std::string(name) + ", budget " + std::to_string(budget) + ", max_leaf " + std::to_string(max_leaf);
                SCOPED_TRACE(what);
                check_tree(tree, tris, max_leaf, true);
                // The budget is handed down as shares; a split may overshoot its share by the few
                // parts its bins did not foresee.
                EXPECT_LE(static_cast<double>(tree.references), static_cast<double>(tris.size()) * (1.0 + budget * 1.05));
                if (name == std::string("tilted strips") && budget >= 0.5) {
                    EXPECT_GT(tree.references, tris.size() * 11 / 10);
                    EXPECT_LT(tree.sah_cost, 0.9 * detail::build_bvh(tris, without_spatial_splits(max_leaf)).sah_cost);
                }
                for (const char* traversal : {"wide", "paired", "stream", "packet"}) {
                    AccelConfig c = bvh({{"split_budget", std::to_string(budget)}, {"max_leaf", std::to_string(max_leaf)}});
                    c.traversal = traversal;
                    test::expect_matches(*make_accelerator(tris, c), ref, what + " " + traversal);
                }
            }
    }
}

// A spatial split's cut of one triangle, held to arithmetic more exact than its own (long double):
// on each side of the plane the box holds the triangle's vertices there and every edge's crossing
// point, and never reaches across the plane; a vertex on the plane belongs to both sides. Triangles
// at scales from 2^-100 to 2^100, planes through vertices and between them. It fails when the
// crossings are rounded to the nearest float instead of outward (tried).
TEST(Bvh, SplitReferenceBoxesHoldTheExactParts) {
    Lcg rng{5};
    const auto next = [&] { return static_cast<double>(rng.next()); };
    using Exact = long double;
    int crossings = 0, tight = 0;
    for (int i = 0; i < 20000; ++i) {
        const double scale = std::ldexp(1.0, static_cast<int>(next() * 200) - 100);
        const auto point = [&] {
            return Vec3{static_cast<float>((next() - 0.5) * scale), static_cast<float>((next() - 0.5) * scale),
                        static_cast<float>((next() - 0.5) * scale)};
        };
        const Triangle tri{point(), point(), point()};
        const int axis = static_cast<int>(next() * 3);
        const Vec3* v[3] = {&tri.v0, &tri.v1, &tri.v2};
        const float lo = std::min({tri.v0[axis], tri.v1[axis], tri.v2[axis]});
        const float hi = std::max({tri.v0[axis], tri.v1[axis], tri.v2[axis]});
        const float pos = i % 4 == 0 ? (*v[i / 4 % 3])[axis] : static_cast<float>(lo + (hi - lo) * next());
        if (!(lo <= pos && pos <= hi)) continue;
        const auto [left, right] = detail::split_reference(tri, tri.bounds(), axis, pos);
        SCOPED_TRACE("triangle " + std::to_string(i));
        ASSERT_FALSE(left.is_empty());
        ASSERT_FALSE(right.is_empty());
        EXPECT_LE(left.hi[axis], pos);
        EXPECT_GE(right.lo[axis], pos);
        const auto holds = [](const Box3& b, const Exact (&x)[3]) {
            for (int k = 0; k < 3; ++k)
                if (!(Exact(b.lo[k]) <= x[k] && x[k] <= Exact(b.hi[k]))) return false;
            return true;
        };
        for (int e = 0; e < 3; ++e) {
            const Vec3& p = *v[e];
            const Vec3& q = *v[e == 2 ? 0 : e + 1];
            const Exact at[3] = {p.x, p.y, p.z};
            if (p[axis] <= pos) {
                EXPECT_TRUE(holds(left, at)) << "vertex " << e << " left";
            }
            if (p[axis] >= pos) {
                EXPECT_TRUE(holds(right, at)) << "vertex " << e << " right";
            }
            if (!((p[axis] < pos && q[axis] > pos) || (p[axis] > pos && q[axis] < pos))) continue;
            const Exact s = (Exact(pos) - p[axis]) / (Exact(q[axis]) - p[axis]);
            Exact x[3];
            for (int k = 0; k < 3; ++k) x[k] = k == axis ? Exact(pos) : p[k] + s * (Exact(q[k]) - p[k]);
            EXPECT_TRUE(holds(left, x)) << "crossing of edge " << e << " left";
            EXPECT_TRUE(holds(right, x)) << "crossing of edge " << e << " right";
            ++crossings;
            // Within a few float steps of a box face: a crossing that decides the box's bounds.
            for (int k = 0; k < 3; ++k)
                if (k != axis && (std::abs(x[k] - Exact(left.lo[k])) <= 4 * std::abs(x[k]) * 0x1p-23L ||
                                  std::abs(x[k] - Exact(left.hi[k])) <= 4 * std::abs(x[k]) * 0x1p-23L))
                    ++tight;
        }
    }
    EXPECT_GT(crossings, 20000);
    EXPECT_GT(tight, 10000);  // the boxes are tight where crossings bound them, which is what is tested
}

// Small triangles scattered through a cube: the object splits' boxes overlap by the triangles' size,
// enough for the search (Stich et al.'s alpha), yet no triangle spans a quarter of any node that is
// searched, so none is cut (bvh_build.cpp, kSpatialReach). Without that rule the build cuts a few
// dozen of them for a higher SAH cost.
TEST(Bvh, NoSpatialSplitAmongTrianglesSmallAgainstEveryNode) {
    std::vector<Triangle> tris;
    Lcg rng{11};
    const auto next = [&] { return rng.next(); };
    for (int i = 0; i < 20000; ++i) {
        const Vec3 p{next(), next(), next()};
        const auto jitter = [&] { return Vec3{next(), next(), next()} * 0.004f - Vec3(0.002f); };
        tris.push_back({p, p + jitter(), p + jitter()});
    }
    for (const double budget : {0.5, 4.0}) {
        BvhBuildOptions o;
        o.split_budget = budget;
        const BvhTree tree = detail::build_bvh(tris, o);
        EXPECT_EQ(tree.references, tris.size()) << "budget " << budget;
        check_tree(tree, tris, 8, true);
    }
}

// Triangles that all share one centroid leave the SAH nothing to split: the object median takes
// over, and the tree stays valid and shallow.
TEST(Bvh, CoincidentCentroidsSplitAtTheMedian) {
    std::vector<Triangle> tris;
    for (int i = 0; i < 5000; ++i) {
        const float s = 1.f + static_cast<float>(i % 50);
        tris.push_back({{-s, 0.f, 0.f}, {s, 0.f, 0.f}, {0.f, 0.f, 0.f}});
    }
    const BvhTree tree = detail::build_bvh(tris, BvhBuildOptions{});
    check_tree(tree, tris, 8);
    EXPECT_LT(tree.depth, 20);
}

TEST(Bvh, SameInputSameTree) {
    const std::vector<Triangle> tris = tilted_strips();
    const BvhTree a = detail::build_bvh(tris, BvhBuildOptions{});
    const BvhTree b = detail::build_bvh(tris, BvhBuildOptions{});
    EXPECT_GT(a.references, tris.size());
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.leaves.size(), b.leaves.size());
    EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)), 0);
    EXPECT_EQ(std::memcmp(a.leaves.data(), b.leaves.data(), a.leaves.size() * sizeof(detail::BvhLeaf)), 0);
}

// The build's tasks change nothing: the same nodes, leaves and SAH cost at every thread count, also
// with tasks from small nodes on, with and without spatial splits.
TEST(Bvh, SameTreeAtAnyThreadCount) {
    const std::vector<Triangle> strips = tilted_strips();
    const Scene& city = test::cached_scene("builtin:city?tris=20000");
    for (const auto& [name, tris] : {std::pair{"tilted strips", std::span<const Triangle>(strips)},
                                     std::pair{"city", std::span<const Triangle>(city.triangles)}})
        for (const double budget : {0.0, 0.5}) {
            BvhBuildOptions one;
            one.threads = 1;
            one.split_budget = budget;
            const BvhTree a = detail::build_bvh(tris, one);
            for (const unsigned threads : {2u, 3u, 0u})
                for (const std::size_t parallel_min : {std::size_t{64}, std::size_t{4096}}) {
                    BvhBuildOptions o = one;
                    o.threads = threads;
                    o.parallel_min = parallel_min;
                    const BvhTree b = detail::build_bvh(tris, o);
                    SCOPED_TRACE(std::string(name) + ", budget " + std::to_string(budget) + ", " +
                                 std::to_string(threads) + " threads, tasks from " + std::to_string(parallel_min));
                    ASSERT_EQ(a.nodes.size(), b.nodes.size());
                    ASSERT_EQ(a.leaves.size(), b.leaves.size());
                    EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)), 0);
                    EXPECT_EQ(std::memcmp(a.leaves.data(), b.leaves.data(), a.leaves.size() * sizeof(detail::BvhLeaf)), 0);
                    EXPECT_EQ(a.sah_cost, b.sah_cost);
                    EXPECT_EQ(a.references, b.references);
                }
        }
}

// Rays that run exactly along the faces of the tree's own boxes (where the slab test's distances are
// 0 x infinity) and start on them.
TEST(Bvh, RaysAlongItsOwnBoxFaces) {
    const Scene& scene = test::cached_scene("builtin:city?tris=5000");
    const BvhTree tree = detail::build_bvh(scene.triangles, BvhBuildOptions{});
    std::vector<Ray> rays;
    const Vec3 c = tree.bounds.center();
    for (std::size_t n = 0; n < tree.nodes.size() && rays.size() < 6000; n += 3) {
        const BvhNode& node = tree.nodes[n];
        for (int k = 0; k < detail::kBvhWidth; ++k) {
            if (node.child[k] == BvhNode::kEmptyChild) continue;
            for (int a = 0; a < 3; ++a) {
                Ray r;
                r.org = c;
                r.org[static_cast<std::size_t>(a)] = node.lo[a][k];
                r.dir = Vec3{1.f, 1.f, 1.f};
                r.dir[static_cast<std::size_t>(a)] = 0.f;  // within the face's plane
                rays.push_back(r);
                r.dir = Vec3{0.f, 0.f, 0.f};
                r.dir[static_cast<std::size_t>(a)] = 1.f;  // from the face, along the axis
                r.org[static_cast<std::size_t>((a + 1) % 3)] = node.hi[(a + 1) % 3][k];
                rays.push_back(r);
            }
        }
    }
    const test::ReferenceAnswers ref = test::compute_reference(scene.triangles, rays);
    test::expect_matches(*make_accelerator(scene.triangles, bvh()), ref, "bvh on its box faces");
    for (const char* config : {"bvh:paired", "bvh:stream", "bvh:packet"})
        test::expect_matches(*make_accelerator(scene.triangles, parse_accel_config(config)), ref,
                             std::string(config) + " on its box faces");
}

// Traces `rays` through `accel` in batches of `batch`, closest and any hit, the work counted into
// `counters` where given; returns how many rays' answers differ from `ref`.
std::size_t differing_answers(const Accelerator& accel, std::span<const Ray> rays, const test::ReferenceAnswers& ref,
                              std::size_t batch, TraversalCounters* counters = nullptr) {
    std::vector<Hit> hits(rays.size());
    std::vector<std::uint8_t> occluded(rays.size(), 2);
    for (std::size_t i = 0; i < rays.size(); i += batch) {
        const std::size_t n = std::min(batch, rays.size() - i);
        accel.intersect(rays.subspan(i, n), std::span(hits).subspan(i, n), counters);
        accel.occluded(rays.subspan(i, n), std::span(occluded).subspan(i, n), counters);
    }
    std::size_t bad = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) bad += !(hits[i] == ref.hits[i]) || occluded[i] != ref.occluded[i];
    return bad;
}

// Every traversal in batches of every size, from one ray to the whole suite in one call (the
// streams' per-thread scratch grows and is reused; packets of eight rays and a short last one), with
// invalid rays mixed in, on every instruction set: the brute-force answers, and every ray counted
// once. The paired traversal walks two rays of a batch at once (paired_batch), each the single-ray
// walk step for step, so its work per ray is the single-ray kernel's whatever the batch (a batch of
// one walks alone, and a batch's last ray may walk alone too).
TEST(Bvh, EveryTraversalInBatchesOfAnySizeMatchesBruteForce) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const test::ReferenceAnswers& suite = test::cached_reference("builtin:spheres?tris=3000", scene.triangles);
    std::vector<Ray> rays = test::sanitized_sample(suite.rays);
    for (std::size_t i = 0; i < rays.size(); i += 97) rays[i].dir = {0.f, 0.f, 0.f};  // invalid: no hit
    const test::ReferenceAnswers ref = test::compute_reference(scene.triangles, rays);
    for (detail::Isa isa : detail::available_isas()) {
        std::optional<TraversalCounters> alone;  // the single-ray kernel's, one ray a batch
        for (const char* traversal : {"wide", "paired", "stream", "packet"}) {
            const std::string config = std::string("bvh:") + traversal + "+" + detail::to_string(isa);
            const auto accel = make_accelerator(scene.triangles, parse_accel_config(config));
            EXPECT_EQ(accel->stats().traversal, traversal);
            for (std::size_t batch : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{7}, std::size_t{256},
                                      std::size_t{1000}, rays.size()}) {
                TraversalCounters counters;
                EXPECT_EQ(differing_answers(*accel, rays, ref, batch, &counters), 0u) << config << ", batches of " << batch;
                EXPECT_EQ(counters.rays, 2 * rays.size());
                EXPECT_GT(counters.nodes, 0u);
                if (traversal != std::string("wide") && traversal != std::string("paired")) continue;
                if (!alone) alone = counters;
                EXPECT_EQ(counters.nodes, alone->nodes) << config << ", batches of " << batch;
                EXPECT_EQ(counters.leaves, alone->leaves) << config << ", batches of " << batch;
                EXPECT_EQ(counters.triangles, alone->triangles) << config << ", batches of " << batch;
            }
        }
    }
}

// The paired walks, the streams and the packets set their rays up eight (AVX-512's packets sixteen) at a time in lanes
// (bvh_kernels.inl, prepare_rays and WatertightLanes), which must give each ray the bits of its own
// set-up: the watertight test's axes where two or three direction components tie in magnitude
// (max_axis takes the first), the swap where the dominant component is negative, the signs of -0 and
// +0 components (the box test's planes). Rays with every such direction, aimed at points of the
// scene, against brute force, in batches that leave partial groups of eight and of sixteen.
TEST(Bvh, RaysSetUpInLanesKeepTiesAndSignsOfTheirDirections) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const float parts[] = {-1.f, -0.f, 0.f, 1.f, 0.5f};
    std::vector<Ray> rays;
    for (std::size_t t = 0; t < scene.triangles.size(); t += 151) {
        const Triangle& tri = scene.triangles[t];
        const Vec3 target = (tri.v0 + tri.v1 + tri.v2) * (1.f / 3.f);
        for (float x : parts)
            for (float y : parts)
                for (float z : parts) {
                    const Vec3 d{x, y, z};
                    if (d == Vec3{}) continue;
                    rays.push_back(Ray{target - d * 4.f, 0.f, d, kInfinity});
                }
    }
    const test::ReferenceAnswers ref = test::compute_reference(scene.triangles, rays);
    std::size_t hit = 0;
    for (const Hit& h : ref.hits) hit += h.is_hit();
    ASSERT_GT(hit, rays.size() / 2);  // the rays meet the scene: the leaf set-up is exercised
    for (detail::Isa isa : detail::available_isas())
        for (const char* traversal : {"paired", "stream", "packet"}) {
            const std::string config = std::string("bvh:") + traversal + "+" + detail::to_string(isa);
            const auto accel = make_accelerator(scene.triangles, parse_accel_config(config));
            for (std::size_t batch : {std::size_t{5}, std::size_t{13}, rays.size()}) {
                EXPECT_EQ(differing_answers(*accel, rays, ref, batch), 0u) << config << ", batches of " << batch;
            }
        }
}

// A leaf that at least as many of a packet's rays reach as it holds triangles is tested one triangle
// at a time in the rays' lanes (bvh_packet.inl, test_leaf_lanes), each lane in its own ray's axis
// order. An octahedron of eight triangles (one or two leaves); every packet's rays come from
// origins on all six sides and the eight diagonals (every dominant axis and sign, so mixed orders
// in a packet) and pass through its vertices and edges (edge functions of zero: the double-precision
// path), its faces' centres and points off it; and rays that start at the centre (t = 0 allowed) or
// end on a face (tfar exactly the hit's t, any hit and closest hit at the bound). Brute force's
// answers, t, u, v and triangle, on every instruction set, in packets of eight and sixteen.
TEST(Bvh, PacketsTestALeafInTheirRaysLanes) {
    const Vec3 v[6] = {{1.f, 0.f, 0.f}, {-1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, -1.f, 0.f}, {0.f, 0.f, 1.f}, {0.f, 0.f, -1.f}};
    std::vector<Triangle> tris;
    for (int x : {0, 1})
        for (int y : {2, 3})
            for (int z : {4, 5}) tris.push_back(Triangle{v[x], v[y], v[z]});
    std::vector<Vec3> targets(std::begin(v), std::end(v));
    for (int a = 0; a < 6; ++a)
        for (int b = a + 1; b < 6; ++b)
            if (!(v[a] + v[b] == Vec3{})) targets.push_back((v[a] + v[b]) * 0.5f);
    for (const Triangle& t : tris) {
        targets.push_back((t.v0 + t.v1 + t.v2) * (1.f / 3.f));
        targets.push_back(t.v0 * 0.7f + t.v1 * 0.2f + t.v2 * 0.1f);
    }
    targets.push_back({0.9f, 0.9f, 0.1f});  // off the octahedron
    std::vector<Vec3> origins;
    for (int a = 0; a < 6; ++a) origins.push_back(v[a] * 3.f + Vec3{0.01f * a, -0.02f * a, 0.015f * a});
    for (float x : {-2.5f, 2.5f})
        for (float y : {-2.f, 2.f})
            for (float z : {-1.5f, 1.5f}) origins.push_back({x, y, z});
    std::vector<Ray> rays;
    for (const Vec3& target : targets)
        for (const Vec3& o : origins) rays.push_back(Ray{o, 0.f, target - o, kInfinity});
    const std::size_t from_outside = rays.size();
    for (const Vec3& target : targets) rays.push_back(Ray{Vec3{0.f, 0.f, 0.f}, 0.f, target, kInfinity});
    const test::ReferenceAnswers outside = test::compute_reference(tris, rays);
    for (std::size_t i = 0; i < from_outside; ++i)
        if (outside.hits[i].is_hit()) rays.push_back(Ray{rays[i].org, 0.f, rays[i].dir, outside.hits[i].t});
    const test::ReferenceAnswers ref = test::compute_reference(tris, rays);
    std::size_t hit = 0;
    for (const Hit& h : ref.hits) hit += h.is_hit();
    ASSERT_GT(hit, rays.size() / 2);
    for (detail::Isa isa : detail::available_isas()) {
        const std::string config = std::string("bvh:packet+") + detail::to_string(isa);
        const auto accel = make_accelerator(tris, parse_accel_config(config));
        for (std::size_t batch : {std::size_t{8}, std::size_t{16}, rays.size()})
            EXPECT_EQ(differing_answers(*accel, rays, ref, batch), 0u) << config << ", batches of " << batch;
    }
}

// The router's streams are a view of its BVH's tree, not a second build; any other accelerator is
// refused.
TEST(Bvh, StreamViewSharesTheTree) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=200");
    const auto single = make_accelerator(scene.triangles, bvh());
    const auto view = detail::bvh_with_traversal(*single, "stream");
    EXPECT_EQ(view->stats().traversal, "stream");
    EXPECT_EQ(view->stats().build_seconds, 0.0);
    EXPECT_EQ(view->stats().tree->nodes, single->stats().tree->nodes);
    EXPECT_THROW(detail::bvh_with_traversal(*make_accelerator(scene.triangles, AccelConfig{"kd"}), "stream"), Error);
    EXPECT_THROW(detail::bvh_with_traversal(*single, "branched"), Error);
}

// A closest-hit ray that meets several children goes to the nearest first (nearest_lane), so that
// its first hit culls the rest. Eight walls across the x axis, one leaf each, all children of the
// root; rays along +x and along -x (one of the two meets the lanes in the reverse of their order,
// whatever order the builder gave them) each test one leaf, in every instruction set's kernel. The
// answers would be exact in any order; this holds the order, which only the counters show (a
// kernel that took the first lane met tests up to all eight leaves).
TEST(Bvh, ClosestHitVisitsTheNearestChildFirst) {
    constexpr int kWalls = 8;
    std::vector<Triangle> walls;
    for (int i = 1; i <= kWalls; ++i) {
        const auto x = static_cast<float>(i);
        walls.push_back({{x, -1.f, -1.f}, {x, 1.f, -1.f}, {x, 1.f, 1.f}});
        walls.push_back({{x, -1.f, -1.f}, {x, 1.f, 1.f}, {x, -1.f, 1.f}});
    }
    BvhBuildOptions options;
    options.max_leaf = 2;
    const BvhTree tree = detail::build_bvh(walls, options);
    ASSERT_EQ(tree.nodes.size(), 1u) << "the root alone, its children the walls' leaves";
    for (std::uint32_t word : tree.nodes[0].child) ASSERT_TRUE(BvhNode::is_leaf(word));
    std::vector<Ray> rays;
    for (float y = -0.85f; y < 0.9f; y += 0.25f)
        for (float z = -0.8f; z < 0.9f; z += 0.3f)
            for (float side : {0.f, kWalls + 1.f}) {
                Ray r;
                r.org = {side, y, z};
                r.dir = {side == 0.f ? 1.f : -1.f, 0.f, 0.f};
                rays.push_back(r);
            }
    const test::ReferenceAnswers ref = test::compute_reference(walls, rays);
    for (detail::Isa isa : detail::available_isas()) {
        const std::string config = std::string("bvh+") + detail::to_string(isa) + "@max_leaf=2";
        const auto accel = make_accelerator(walls, parse_accel_config(config));
        std::vector<Hit> hits(rays.size());
        TraversalCounters counters;
        accel->intersect(rays, hits, &counters);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            ASSERT_EQ(hits[i], ref.hits[i]) << config << ", ray " << i;
            EXPECT_EQ(hits[i].t, 1.f) << config << ", ray " << i;
            EXPECT_EQ(hits[i].prim / 2, rays[i].dir[0] > 0.f ? 0u : kWalls - 1u) << config << ", ray " << i;
        }
        EXPECT_EQ(counters.nodes, rays.size()) << config;
        EXPECT_EQ(counters.leaves, rays.size()) << config << ": a leaf past the nearest was tested";
    }
}

TEST(Bvh, EmptySceneMissesEverything) {
    const auto accel = make_accelerator({}, bvh());
    std::vector<Ray> rays(5);
    for (Ray& r : rays) r.dir = {0.f, 0.f, 1.f};
    std::vector<Hit> hits(rays.size(), Hit{1.f, 7, 0.f, 0.f});
    std::vector<std::uint8_t> occluded(rays.size(), 1);
    TraversalCounters counters;
    accel->intersect(rays, hits, &counters);
    accel->occluded(rays, occluded);
    for (const Hit& h : hits) EXPECT_FALSE(h.is_hit());
    for (std::uint8_t o : occluded) EXPECT_EQ(o, 0);
    EXPECT_EQ(counters.rays, rays.size());
    EXPECT_EQ(accel->stats().memory_bytes, 0u);
}

// Batches with nothing to walk, on every traversal: empty, and every ray invalid (a zero direction,
// a NaN origin, tnear past tfar): each answered as a miss, not occluded, and counted.
TEST(Bvh, BatchesOfOnlyInvalidRaysOrNoneAnswerMisses) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=200");
    std::vector<Ray> rays(5);
    for (Ray& r : rays) r.dir = {0.f, 0.f, 1.f};
    rays[0].dir = {0.f, 0.f, 0.f};
    rays[1].org.x = std::nanf("");
    rays[2].tnear = 2.f, rays[2].tfar = 1.f;
    rays[3].dir = {0.f, 0.f, 0.f};
    rays[4].dir.y = std::numeric_limits<float>::infinity();
    for (const char* traversal : {"wide", "paired", "stream", "packet"}) {
        const auto accel = make_accelerator(scene.triangles, parse_accel_config(std::string("bvh:") + traversal));
        TraversalCounters counters;
        accel->intersect({}, {}, &counters);
        accel->occluded({}, {}, &counters);
        EXPECT_EQ(counters.rays, 0u) << traversal;
        std::vector<Hit> hits(rays.size(), Hit{1.f, 7, 0.f, 0.f});
        std::vector<std::uint8_t> occluded(rays.size(), 1);
        accel->intersect(rays, hits, &counters);
        accel->occluded(rays, occluded, &counters);
        for (const Hit& h : hits) EXPECT_FALSE(h.is_hit()) << traversal;
        for (std::uint8_t o : occluded) EXPECT_EQ(o, 0) << traversal;
        EXPECT_EQ(counters.rays, 2 * rays.size()) << traversal;
    }
}

TEST(Bvh, RefusesBadParameters) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=200");
    for (const auto& [k, v] : std::vector<std::pair<std::string, std::string>>{
             {"max_leaf", "0"}, {"max_leaf", "9"}, {"bins", "1"}, {"bins", "257"}, {"traversal_cost", "0"},
             {"intersection_cost", "-1"}, {"split_budget", "-0.5"}, {"split_budget", "5"},
             {"leaf_size", "4"}})
        EXPECT_THROW(make_accelerator(scene.triangles, bvh({{k, v}})), Error) << k << "=" << v;
    AccelConfig c = bvh();
    c.traversal = "branched";
    EXPECT_THROW(make_accelerator(scene.triangles, c), Error);
}

// The router's measure: a frame's primary rays and the shadow rays of their hits are coherent, its
// diffuse bounces and random directions are not, and invalid rays do not count.
TEST(Routed, CoherenceTellsFrameRaysFromBounces) {
    const Scene& scene = test::cached_scene("builtin:city?tris=5000");
    const auto kd = make_accelerator(scene.triangles, AccelConfig{"kd"});
    ShadingOptions diffuse;
    diffuse.shading = Shading::diffuse;
    const FrameRays frame = frame_rays(scene, 64, 64, 16, *kd);
    const FrameRays bounces = frame_rays(scene, 64, 64, 16, *kd, diffuse);
    for (const FrameRays::Packet& p : frame.packets) {
        EXPECT_GT(detail::batch_coherence(std::span(frame.primary).subspan(p.primary, p.primary_count)), 0.9f);
        if (p.secondary_count > 16) {
            EXPECT_GT(detail::batch_coherence(std::span(frame.secondary).subspan(p.secondary, p.secondary_count)), 0.9f);
        }
    }
    for (const FrameRays::Packet& p : bounces.packets) {
        if (p.secondary_count > 16) {
            EXPECT_LT(detail::batch_coherence(std::span(bounces.secondary).subspan(p.secondary, p.secondary_count)), 0.6f);
        }
    }
    std::vector<Ray> invalid(8);
    for (Ray& r : invalid) r.dir = {0.f, 0.f, 0.f};
    invalid[3].dir = {1.f, 0.f, 0.f};
    EXPECT_EQ(detail::batch_coherence(invalid), 1.f);
    EXPECT_EQ(detail::batch_coherence({}), 1.f);
}

// The measured route. The first kPrior batches go by coherence, untimed; then, while it learns,
// interleaved runs: kRounds rounds, each kPerPath batches per path, path after path, all but the
// first of a path's batches timed; then the path of least time per ray takes the runs that are not
// timed, and a timed run interleaves it with the paths near it, and with the far ones less often.
// `take(n, prior)` picks n batches, observing each, and returns how many were timed, recording for each timed one
// `per_ray[path]` seconds per ray (times `tile_cost(batch)`, the batch's own cost, when given) on a
// batch of `rays` rays, of which none hit (or `tile_hits(batch)` of them, when given).
struct PickerRun {
    detail::RoutePicker& picker;
    std::vector<double> per_ray;
    std::function<double(std::uint64_t)> tile_cost = [](std::uint64_t) { return 1.0; };
    std::function<double(std::uint64_t)> tile_hits = [](std::uint64_t) { return 0.0; };
    int paths_seen[detail::RoutePicker::kMaxPaths] = {};
    std::uint64_t batch = 0;
    int take(int n, int prior = 0, std::size_t rays = 100) {
        int timed = 0;
        for (int i = 0; i < n; ++i, ++batch) {
            const detail::RoutePicker::Choice c = picker.pick(prior);
            ++paths_seen[c.path];
            const auto hits = static_cast<std::size_t>(tile_hits(batch) * static_cast<double>(rays));
            picker.observe(rays, hits);
            if (!c.timed) continue;
            ++timed;
            picker.record(c.path, per_ray[static_cast<std::size_t>(c.path)] * tile_cost(batch) * static_cast<double>(rays),
                          rays, hits);
        }
        return timed;
    }
};

TEST(Routed, PickerLearnsInInterleavedRunsThenTakesThePathOfLeastTimePerRay) {
    using detail::RoutePicker;
    RoutePicker picker;
    for (std::uint64_t i = 0; i < RoutePicker::kPrior; ++i) {  // coherence alone, nothing timed
        const RoutePicker::Choice c = picker.pick(static_cast<int>(i % 2));
        EXPECT_EQ(c.path, static_cast<int>(i % 2));
        EXPECT_FALSE(c.timed);
    }
    // Learning: each run kRounds rounds of kPerPath batches per path, in the same order in every
    // round of the run, all but a path's first batch timed; the order varies from run to run.
    constexpr std::uint64_t per = RoutePicker::kPerPath;
    ASSERT_EQ(picker.run_length(), 2 * per * RoutePicker::kRounds);
    int runs_led_by[2] = {};
    for (std::uint64_t run = 0; run < RoutePicker::kLearnRuns; ++run) {
        int first = -1;
        for (std::uint64_t round = 0; round < RoutePicker::kRounds; ++round)
            for (std::uint64_t i = 0; i < 2 * per; ++i) {
                const RoutePicker::Choice c = picker.pick(1);
                if (round == 0 && i == 0) first = c.path;
                EXPECT_EQ(c.path, i < per ? first : 1 - first) << "run " << run << " round " << round << " batch " << i;
                EXPECT_EQ(c.timed, i % per != 0) << "run " << run << " round " << round << " batch " << i;
                // Batches of different sizes: per ray the packets take 3 units, the BVH 2.
                const std::size_t rays = 32 + 7 * i;
                if (c.timed) picker.record(c.path, (c.path == 0 ? 3.0 : 2.0) * static_cast<double>(rays), rays, rays / 2);
            }
        ++runs_led_by[first];
    }
    EXPECT_GT(runs_led_by[0], 0);
    EXPECT_GT(runs_led_by[1], 0);
    EXPECT_DOUBLE_EQ(picker.cost(0), 3.0);
    EXPECT_DOUBLE_EQ(picker.cost(1), 2.0);
    EXPECT_EQ(picker.samples(0), RoutePicker::kLearnRuns * RoutePicker::kRounds * (per - 1));
    // Known: the BVH, whatever the prior, except in the runs timed on the packets.
    PickerRun run{picker, {3.0, 2.0}};
    const int n = 8000;
    const int timed = run.take(n, 0);
    EXPECT_GT(run.paths_seen[1], n * 9 / 10);
    EXPECT_GT(run.paths_seen[0], 0);  // timed runs reach the slower path too
    EXPECT_LE(run.paths_seen[0], timed);
    // The workload changes: the BVH's rays get dearer, and its timed runs tell.
    run.per_ray = {3.0, 9.0};
    run.take(40000, 1);
    EXPECT_GT(picker.cost(1), picker.cost(0));
    EXPECT_EQ(picker.fastest(1), 0);
}

// With the streams, three paths, learned interleaved; the cheapest per ray is taken.
TEST(Routed, PickerChoosesAmongThreePaths) {
    using detail::RoutePicker;
    RoutePicker picker(3);
    EXPECT_EQ(picker.paths(), 3);
    for (std::uint64_t i = 0; i < RoutePicker::kPrior; ++i) EXPECT_EQ(picker.pick(1).path, 1);  // the prior
    PickerRun run{picker, {3.0, 2.0, 1.0}};
    const auto learning = static_cast<int>(RoutePicker::kLearnRuns * picker.run_length());
    EXPECT_EQ(run.take(learning, 1), learning / static_cast<int>(RoutePicker::kPerPath) *
                                         static_cast<int>(RoutePicker::kPerPath - 1));
    EXPECT_EQ(run.paths_seen[0], run.paths_seen[1]);  // interleaved
    EXPECT_EQ(run.paths_seen[1], run.paths_seen[2]);
    EXPECT_EQ(picker.fastest(0), 2);
    EXPECT_EQ(picker.fastest(1), 2);
    EXPECT_TRUE(picker.far(0, 2));
    EXPECT_TRUE(picker.far(1, 2));
    run.per_ray = {3.0, 2.0, 20.0};  // the streams now dearest: their timed runs raise their cost
    run.take(40000, 2);
    EXPECT_EQ(picker.fastest(2), 1);
    EXPECT_FALSE(picker.far(0, 1));  // the packets within kFar of the single rays
    EXPECT_TRUE(picker.far(2, 1));

    // A path with nothing counted (no batch of it recorded) is not chosen, and keeps the
    // choice from being clear.
    RoutePicker half(3);
    for (std::uint64_t i = 0; i < RoutePicker::kPrior + RoutePicker::kLearnRuns * half.run_length(); ++i) half.pick(1);
    half.record(0, 3.0, 1, 0);
    half.record(1, 1.0, 1, 1);
    EXPECT_EQ(half.cost(2), 0.0);
    EXPECT_EQ(half.fastest(0), 1);
    EXPECT_FALSE(half.far(2, 1));
}

// A path left out of a kind (the router's study-tree packets on incoherent batches) is neither
// chosen nor timed, however cheap it would be: the others learn in runs of their own length.
TEST(Routed, PickerLeavesOutAPath) {
    using detail::RoutePicker;
    RoutePicker picker(4, 1u);
    EXPECT_FALSE(picker.takes_part(0));
    EXPECT_TRUE(picker.takes_part(1) && picker.takes_part(2) && picker.takes_part(3));
    EXPECT_EQ(picker.run_length(), 3 * RoutePicker::kPerPath * RoutePicker::kRounds);
    for (std::uint64_t i = 0; i < RoutePicker::kPrior; ++i) EXPECT_EQ(picker.pick(1).path, 1);  // the prior
    PickerRun run{picker, {0.5, 2.0, 3.0, 1.5}};  // path 0 would be the cheapest
    const auto learning = static_cast<int>(RoutePicker::kLearnRuns * picker.run_length());
    EXPECT_EQ(run.take(learning, 1), learning / static_cast<int>(RoutePicker::kPerPath) *
                                         static_cast<int>(RoutePicker::kPerPath - 1));
    EXPECT_EQ(run.paths_seen[0], 0);
    EXPECT_EQ(run.paths_seen[1], run.paths_seen[2]);
    EXPECT_EQ(run.paths_seen[2], run.paths_seen[3]);
    run.take(20000, 1);
    EXPECT_EQ(run.paths_seen[0], 0);
    EXPECT_EQ(picker.samples(0), 0u);
    EXPECT_EQ(picker.fastest(1), 3);
    // A mask that would leave fewer than two paths, or names paths not held, leaves none out.
    const RoutePicker two(2, 1u), three(3, 3u);
    EXPECT_TRUE(two.takes_part(0) && three.takes_part(0) && three.takes_part(1));
    EXPECT_EQ(three.run_length(), 3 * RoutePicker::kPerPath * RoutePicker::kRounds);
    EXPECT_EQ(RoutePicker(2, 4u).run_length(), 2 * RoutePicker::kPerPath * RoutePicker::kRounds);
}

// A frame's tiles in order, where a tile on the object costs ten times one of background: the
// object fills the middle columns of rows 4 to 11 of 16 x 16 tiles. The packets take 1.0 per ray,
// the single rays 1.3, the streams 1.25, the BVH's packets 1.15. Every path is timed on tiles of the same stretches, so the
// packets are taken; timed in runs of consecutive tiles, a path could see mostly the object where
// another saw mostly background.
TEST(Routed, PickerComparesPathsOnTheSameStretchesOfTiles) {
    using detail::RoutePicker;
    const auto on_object = [](std::uint64_t batch) {
        const std::uint64_t tile = batch % 256, row = tile / 16, column = tile % 16;
        return row >= 4 && row < 12 && column >= 5 && column < 11;
    };
    const auto tile_cost = [&](std::uint64_t batch) { return on_object(batch) ? 10.0 : 1.0; };
    const auto tile_hits = [&](std::uint64_t batch) { return on_object(batch) ? 1.0 : 0.0; };
    for (const int paths : {2, 3, 4}) {
        RoutePicker picker(paths);
        PickerRun run{picker, {1.0, 1.3, 1.25, 1.15}, tile_cost, tile_hits};
        run.take(6 * 256, 1);  // six frames
        EXPECT_EQ(picker.fastest(1), 0) << paths << " paths: per ray packets " << picker.cost(0) << ", single rays "
                                        << picker.cost(1) << ", streams " << picker.cost(2);
        const int later = 4 * 256;
        const int before = run.paths_seen[0];
        run.take(later, 1);
        EXPECT_GT(run.paths_seen[0] - before, later * 9 / 10) << paths << " paths";
    }
}

// The bunny's camera tiles (docs/INCOHERENT.md, sixth round): a tile of background costs every path
// 0.1 per ray; one on the object costs the kd-tree's packets (path 0) 1.5, the BVH's packets
// (path 1) 1.0; a tile on the object's edge costs the kd packets as much as one on it (a packet
// costs what its dearest ray does), the BVH's packets in proportion. Timed mostly on background,
// the kd packets' plain time per ray undercuts the BVH packets', timed mostly on the object; per
// class of hit fraction, weighted by every path's timed rays in each, the BVH's packets are the
// cheaper, as over a whole frame.
TEST(Routed, PickerComparesPathsOnTheSameMixOfHitFractions) {
    detail::RoutePicker picker(2);
    const std::size_t rays = 256;
    const auto tile = [&](int path, std::size_t hits) {
        const double h = static_cast<double>(hits) / rays, object = hits == 0 ? 0.0 : path == 0 ? 1.0 : h;
        picker.record(path, static_cast<double>(rays) * (0.1 + object * (path == 0 ? 1.4 : 0.9)), rays, hits);
    };
    for (int i = 0; i < 16; ++i) tile(0, 0), tile(1, rays);
    for (int i = 0; i < 4; ++i) tile(0, 64), tile(1, 64);
    for (int i = 0; i < 4; ++i) tile(0, rays), tile(1, 0);
    const double plain0 = picker.seconds(0) / picker.rays(0), plain1 = picker.seconds(1) / picker.rays(1);
    EXPECT_LT(plain0, plain1);
    const auto m = picker.mix();  // rays hitting none, some, all
    EXPECT_DOUBLE_EQ(m[0], 20.0 / 48);
    EXPECT_DOUBLE_EQ(m[1], 8.0 / 48);
    EXPECT_DOUBLE_EQ(m[2], 20.0 / 48);
    EXPECT_NEAR(picker.cost(0), m[0] * 0.1 + (m[1] + m[2]) * 1.5, 1e-12);
    EXPECT_NEAR(picker.cost(1), m[0] * 0.1 + m[1] * (0.1 + 0.9 / 4) + m[2] * 1.0, 1e-12);
    EXPECT_EQ(picker.fastest(0), 1);

    // For the report's figures (cost(), mix()), a class that some path was not timed in (here the kd
    // packets' tiles of all hits, the BVH packets' of some) is left out for every path; the choice
    // compares paths two at a time (PickerLearnsAgainOnAClassItWasNotTimedOn).
    detail::RoutePicker gap(2);
    gap.record(0, 10.0, 100, 0), gap.record(0, 50.0, 100, 30), gap.record(1, 5.0, 100, 0), gap.record(1, 7.0, 100, 100);
    EXPECT_DOUBLE_EQ(gap.mix()[0], 1.0);
    EXPECT_DOUBLE_EQ(gap.cost(0), 0.1);
    EXPECT_DOUBLE_EQ(gap.cost(1), 0.05);
    // No class shared: the plain time per ray.
    detail::RoutePicker apart(2);
    apart.record(0, 10.0, 100, 0), apart.record(0, 50.0, 100, 30), apart.record(1, 7.0, 100, 100);
    EXPECT_DOUBLE_EQ(apart.cost(0), 60.0 / 200);
    EXPECT_DOUBLE_EQ(apart.cost(1), 7.0 / 100);
    // Batches all of one class (a frame inside a building: every ray hits): the plain time per ray.
    detail::RoutePicker alike(2);
    for (int i = 0; i < 10; ++i) alike.record(0, 2.0 + i, 100, 100), alike.record(1, 1.0 + i, 100, 100);
    EXPECT_DOUBLE_EQ(alike.cost(0), alike.seconds(0) / alike.rays(0));
    EXPECT_DOUBLE_EQ(alike.cost(1), alike.seconds(1) / alike.rays(1));
}

// The bunny's camera tiles in order (24 x 24 tiles; the object in rows 17 to 22, columns 6 to 17):
// the learning runs see only background, where the kd-tree's packets (path 0, 1.0 per ray) beat the
// BVH's (path 1, 1.1); on the object they take 15 per ray, the BVH's packets 8. The first frame's
// one timed run of the usual kind (run 21, batches 386 to 403) ends before the object: only the run
// timed because tiles of all hits hold kCover of the rays and neither path was timed on one lets
// the BVH's packets be chosen within the first frame; they take the object's tiles from then on.
TEST(Routed, PickerLearnsAgainOnAClassItWasNotTimedOn) {
    using detail::RoutePicker;
    const auto on_object = [](std::uint64_t batch) {
        const std::uint64_t tile = batch % 576, row = tile / 24, column = tile % 24;
        return row >= 17 && row < 23 && column >= 6 && column < 18;
    };
    RoutePicker picker(2);
    const std::size_t rays = 256;
    int object_tiles = 0, object_on_bvh = 0;
    const auto frame = [&](std::uint64_t first) {
        for (std::uint64_t batch = first; batch < first + 576; ++batch) {
            const RoutePicker::Choice c = picker.pick(0);
            const bool object = on_object(batch);
            if (first > 0 && object) ++object_tiles, object_on_bvh += c.path == 1;
            const std::size_t hits = object ? rays : 0;
            picker.observe(rays, hits);
            if (!c.timed) continue;
            const double per_ray = object ? (c.path == 0 ? 15.0 : 8.0) : (c.path == 0 ? 1.0 : 1.1);
            picker.record(c.path, per_ray * static_cast<double>(rays), rays, hits);
        }
    };
    frame(0);
    EXPECT_FALSE(picker.uncovered());
    EXPECT_EQ(picker.fastest(0), 1) << "per ray: kd packets " << picker.cost(0) << ", BVH packets " << picker.cost(1);
    frame(576);
    frame(2 * 576);
    EXPECT_GT(object_on_bvh, object_tiles * 9 / 10) << object_on_bvh << " of " << object_tiles;

    // A class the runs never cover (here every batch is seen with all rays hitting and timed as if
    // none did) makes runs timed again ever more seldom: after 4, 8, 16 ... 256 runs, not one run in
    // four for good, whose runs would give the far path (ten times the cost) its share of those in
    // which far paths join (702 batches of it, measured so).
    RoutePicker never(2);
    const std::uint64_t runs = 1000, batches = RoutePicker::kPrior + runs * never.run_length();
    int far_batches = 0;
    for (std::uint64_t i = 0; i < batches; ++i) {
        const RoutePicker::Choice c = never.pick(0);
        never.observe(rays, rays);
        far_batches += c.path == 1;
        if (c.timed) never.record(c.path, (c.path == 0 ? 1.0 : 10.0) * static_cast<double>(rays), rays, 0);
    }
    EXPECT_TRUE(never.uncovered());
    EXPECT_LT(far_batches, 400);

    // Two paths are compared on the classes both were timed in: a slow path timed on background
    // only (path 2) does not leave the object's tiles out of the others' comparison, where one mix
    // for all would (cost() and mix(), the report's figures).
    RoutePicker pairs(3);
    pairs.observe(1000, 0), pairs.observe(3000, 3000);
    pairs.record(0, 100.0, 100, 0), pairs.record(0, 1500.0, 100, 100);
    pairs.record(1, 110.0, 100, 0), pairs.record(1, 800.0, 100, 100);
    pairs.record(2, 300.0, 100, 0);
    EXPECT_EQ(pairs.fastest(0), 1);
    EXPECT_LT(pairs.cost(0), pairs.cost(1));  // on background alone, the common mix
    const auto c = pairs.compared(0, 1);
    EXPECT_DOUBLE_EQ(c[0], 0.25 * 1.0 + 0.75 * 15.0);
    EXPECT_DOUBLE_EQ(c[1], 0.25 * 1.1 + 0.75 * 8.0);
    EXPECT_TRUE(pairs.far(2, 1));  // on background, the class they share: 3.0 against 1.1
    EXPECT_TRUE(pairs.far(0, 1));  // 11.5 against 6.3
    EXPECT_FALSE(pairs.uncovered());  // the one path in contention was timed in both classes

    // A class below kCover of the rays, or one that a path left out lacks, does not make a run learn.
    RoutePicker few(2), left(3, 1u);
    few.observe(1000, 0), few.observe(10, 10), few.record(0, 1.0, 100, 0), few.record(1, 1.0, 100, 0);
    EXPECT_FALSE(few.uncovered());
    few.observe(100, 100);
    EXPECT_TRUE(few.uncovered());
    left.observe(100, 100), left.record(1, 1.0, 100, 100), left.record(2, 1.0, 100, 100);
    EXPECT_FALSE(left.uncovered());
    // The classes are weighted by every batch observed, not only the timed ones.
    EXPECT_DOUBLE_EQ(few.mix()[0], 1.0);  // all hits left out: neither path was timed on such a batch
    few.record(0, 1.0, 100, 100), few.record(1, 2.0, 100, 100);
    EXPECT_NEAR(few.mix()[0], 1000.0 / 1110, 1e-12);
    EXPECT_NEAR(few.mix()[2], 110.0 / 1110, 1e-12);
}

// Once the picker knows: one run in kSample is timed; it interleaves the fastest with every path
// within kFar of it, and with one that costs more than kFar times the fastest in kSampleFar /
// kSample of them (in the others the fastest runs alone, timed, then takes the run's rest).
TEST(Routed, PickerTimesFewRunsOnceItKnows) {
    using detail::RoutePicker;
    RoutePicker close, clear;
    const auto learning = static_cast<int>(RoutePicker::kPrior + RoutePicker::kLearnRuns * close.run_length());
    PickerRun near_run{close, {1.0, 1.2}}, far_run{clear, {1.0, 3.0}};
    const double rounds = RoutePicker::kRounds, per = RoutePicker::kPerPath, length = static_cast<double>(close.run_length());
    const auto learned = static_cast<int>(RoutePicker::kLearnRuns * 2 * rounds * (per - 1));
    EXPECT_EQ(near_run.take(learning), learned);
    EXPECT_EQ(far_run.take(learning), learned);
    PickerRun near{close, {1.0, 1.2}}, far{clear, {1.0, 3.0}};
    const int n = 512000;
    const double timed_runs = n / length / RoutePicker::kSample, joined = 1.0 / (RoutePicker::kSampleFar / RoutePicker::kSample);
    const double near_timed = timed_runs * 2 * rounds * (per - 1);
    const double far_timed = timed_runs * ((1 - joined) + joined * 2) * rounds * (per - 1);
    EXPECT_NEAR(near.take(n), near_timed, near_timed / 4);
    EXPECT_NEAR(far.take(n), far_timed, far_timed / 4);
    const double near_share = timed_runs * rounds * per, far_share = timed_runs * joined * rounds * per;
    EXPECT_NEAR(near.paths_seen[1], near_share, near_share / 4);
    EXPECT_NEAR(far.paths_seen[1], far_share, far_share / 4);
}

// Measured or not, the route changes no answer, and the work counted is that of the path that
// answered (a sampled batch's second tracing is not counted).
TEST(Routed, MeasuredRouteCountsOneTracingPerRay) {
    const Scene& scene = test::cached_scene("builtin:city?tris=5000");
    const auto routed = make_accelerator(scene.triangles, parse_accel_config("auto"));
    const auto exact = make_accelerator(scene.triangles, AccelConfig{"bvh"});
    const FrameRays frame = frame_rays(scene, 64, 64, 16, *exact);
    std::vector<Hit> hits(frame.primary.size()), expected(frame.primary.size());
    exact->intersect(frame.primary, expected);
    TraversalCounters counters;
    for (const FrameRays::Packet& p : frame.packets)
        routed->intersect(std::span(frame.primary).subspan(p.primary, p.primary_count),
                          std::span(hits).subspan(p.primary, p.primary_count), &counters);
    EXPECT_EQ(hits, expected);
    EXPECT_EQ(counters.rays, frame.primary.size());
}

// The paths by name: `auto` holds the BVH's streams and packets unless told not to, and only when it
// measures (coherence alone never names them).
TEST(Routed, StreamsAndBvhPacketsArePathsOfTheMeasuredRoute) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=200");
    auto setting = [&](const std::string& spec, const std::string& name) {
        return make_accelerator(scene.triangles, parse_accel_config(spec))->stats().setting(name).value_or("");
    };
    for (const std::string name : {"streams", "bvh_packets"}) {
        EXPECT_EQ(setting("auto", name), "on");
        EXPECT_EQ(setting("auto@" + name + "=off", name), "off");
        EXPECT_EQ(setting("auto@route=coherence", name), "off");
        EXPECT_EQ(setting("auto@route=coherence," + name + "=off", name), "off");
        try {  // asked for by name where the route cannot hold it: refused, not left out
            make_accelerator(scene.triangles, parse_accel_config("auto@route=coherence," + name + "=on"));
            ADD_FAILURE() << name << "=on accepted with route=coherence";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(name + "=on contradicts route=coherence"), std::string::npos)
                << e.what();
        }
        EXPECT_THROW(make_accelerator(scene.triangles, parse_accel_config("auto@" + name + "=maybe")), Error);
    }
    EXPECT_EQ(setting("auto@streams=off", "bvh_packets"), "on");
    // Switches, as the kd-tree's and Embree's are: on/off, true/false, 1/0 (Python's False is "false").
    EXPECT_EQ(setting("auto@streams=false,bvh_packets=0", "streams"), "off");
    EXPECT_EQ(setting("auto@streams=false,bvh_packets=0", "bvh_packets"), "off");
    EXPECT_EQ(setting("auto@streams=true", "streams"), "on");
    EXPECT_EQ(setting("auto@bvh_packets=off", "streams"), "on");
    // With the BVH's own packets for coherent batches, they are the first path, not a fourth.
    EXPECT_EQ(setting("auto", "packets"), "kd");
    EXPECT_EQ(setting("auto@packets=bvh", "bvh_packets"), "on");
    EXPECT_EQ(setting("auto@packets=bvh,bvh_packets=on", "bvh_packets"), "on");
    // There the BVH's packets are the coherent path, which the coherence route holds too.
    EXPECT_EQ(setting("auto@packets=bvh,route=coherence,bvh_packets=on", "bvh_packets"), "on");
    try {
        make_accelerator(scene.triangles, parse_accel_config("auto@packets=bvh,bvh_packets=off"));
        ADD_FAILURE() << "bvh_packets=off accepted with packets=bvh";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bvh_packets=off contradicts packets=bvh"), std::string::npos) << e.what();
    }
    EXPECT_EQ(setting("auto@packets=bvh", "streams"), "on");
}

// A caller who names no configuration (the C API's NULL, Python's kind=None) gets the route over one
// BVH on the CPU, and the kd-tree on the GPU, which traces the trees only.
TEST(Routed, IsTheDefaultOnTheCpu) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=200");
    const AccelConfig cpu = default_accel_config();
    EXPECT_EQ(cpu.kind, "auto");
    EXPECT_EQ(cpu.device, "cpu");
    const AccelStats s = make_accelerator(scene.triangles, cpu)->stats();
    EXPECT_EQ(s.name, "auto");
    EXPECT_EQ(s.setting("packets"), "bvh");
    const AccelConfig gpu = default_accel_config("cuda");
    EXPECT_EQ(gpu.kind, "kd");
    EXPECT_EQ(gpu.simd, "off");
    EXPECT_EQ(gpu.device, "cuda");
}

// `packets=bvh` builds one tree for every path: the route's memory is the BVH's, and its packets are
// the BVH's: eight rays at a time, sixteen with AVX-512's kernels.
TEST(Routed, BvhPacketsRouteHoldsOneTree) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const AccelStats one = make_accelerator(scene.triangles, AccelConfig{"bvh"})->stats();
    const AccelStats routed = make_accelerator(scene.triangles, parse_accel_config("auto@packets=bvh"))->stats();
    const AccelStats two = make_accelerator(scene.triangles, parse_accel_config("auto"))->stats();
    EXPECT_EQ(routed.memory_bytes, one.memory_bytes);
    EXPECT_GT(two.memory_bytes, one.memory_bytes);  // the kd-tree and the BVH
    const AccelStats packets = make_accelerator(scene.triangles, parse_accel_config("bvh:packet"))->stats();
    EXPECT_EQ(packets.simd_lanes, packets.setting("isa") == "avx512" ? 16 : detail::kBvhWidth);
    EXPECT_EQ(routed.simd_lanes, packets.simd_lanes);
    for (const detail::Isa isa : detail::available_isas()) {
        const std::string name = detail::to_string(isa);
        const AccelStats s = make_accelerator(scene.triangles, parse_accel_config("bvh:packet+" + name))->stats();
        EXPECT_EQ(s.simd_lanes, isa == detail::Isa::avx512 ? 16 : detail::kBvhWidth) << name;
    }
    EXPECT_EQ(one.simd_lanes, 0);
}

// While it learns, the route gives runs of the suite's batches (incoherent: random directions) to
// each of its paths taking part (the BVH's three; a study tree's packets take no part in
// incoherent batches, RoutePicker), with the same answers, and the work counted is one tracing per
// ray whichever path answered.
class RoutedPaths : public ::testing::TestWithParam<std::pair<std::string, std::vector<std::string>>> {};

TEST_P(RoutedPaths, StreamedBatchesAnswerAsBruteForce) {
    const auto& [spec, names] = GetParam();
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const test::ReferenceAnswers& ref = test::cached_reference("builtin:spheres?tris=3000", scene.triangles);
    const auto routed = make_accelerator(scene.triangles, parse_accel_config(spec));
    for (int round = 0; round < 3; ++round) {  // enough batches to learn and sample
        std::vector<Hit> hits(ref.rays.size());
        std::vector<std::uint8_t> occluded(ref.rays.size());
        TraversalCounters counters;
        for (std::size_t i = 0; i < ref.rays.size(); i += 64) {
            const std::size_t n = std::min<std::size_t>(64, ref.rays.size() - i);
            routed->intersect(std::span(ref.rays).subspan(i, n), std::span(hits).subspan(i, n), &counters);
            routed->occluded(std::span(ref.rays).subspan(i, n), std::span(occluded).subspan(i, n));
        }
        EXPECT_EQ(hits, ref.hits);
        EXPECT_EQ(occluded, ref.occluded);
        EXPECT_EQ(counters.rays, ref.rays.size());
    }
    // Each path taking part answered some of them, the study tree's packets none: "closest packets
    // P paired S stream T bvh-packets B; any ...", for closest and any hits.
    const std::string routes = routed->stats().setting("routed").value_or("");
    const bool study_packets = spec == "auto";
    EXPECT_EQ(routes.find(" bvh-packets ") != std::string::npos, study_packets) << routes;
    for (const std::string name : {"packets", "paired", "stream", "bvh-packets"}) {
        if (name == "bvh-packets" && !study_packets) continue;
        const std::string path = " " + name + " ";
        for (std::size_t at = routes.find(path), seen = 0; seen < 2; at = routes.find(path, at + 1), ++seen) {
            ASSERT_NE(at, std::string::npos) << path << "in: " << routes;
            const double share = std::stod(routes.substr(at + path.size()));
            if (std::ranges::find(names, name) != names.end()) EXPECT_GT(share, 0.0) << path << "in: " << routes;
            else EXPECT_EQ(share, 0.0) << path << "in: " << routes;
        }
    }
}

// Before any ray, the route's report says so, not shares of 0 / 0 written as zeros (audit, 2026-12-07).
TEST(Routed, ReportsNoneRoutedBeforeAnyRay) {
    const std::vector<Triangle> tris = test::soup(1.f);
    const auto routed = make_accelerator(tris, parse_accel_config("auto"));
    EXPECT_EQ(routed->stats().setting("routed"), "closest none routed; any none routed");
}

INSTANTIATE_TEST_SUITE_P(Routed, RoutedPaths,
                         ::testing::Values(std::pair{std::string("auto"), std::vector<std::string>{"paired", "stream", "bvh-packets"}},
                                           std::pair{std::string("auto@packets=bvh"), std::vector<std::string>{"packets", "paired", "stream"}}),
                         [](const auto& info) { return info.index == 0 ? std::string("KdPackets") : std::string("BvhPackets"); });

}  // namespace
}  // namespace cellrt
