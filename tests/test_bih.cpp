// The BIH beyond the checks every structure faces (test_structures.cpp): build variants stay exact,
// rays in its own clip planes, no duplicated references, the same hierarchy at any thread count,
// the build report and parameter validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "bih/bih_tree.hpp"
#include "cellrt/error.hpp"
#include "ray_suite.hpp"
#include "scenes.hpp"

namespace cellrt {
namespace {

const std::vector<std::string> kTraversals = {"branched", "branchless"};

AccelConfig bih(const std::string& traversal, std::map<std::string, std::string> params = {}) {
    AccelConfig c{"bih", traversal};
    c.params = std::move(params);
    return c;
}

TEST(Bih, BuildVariantsMatchBruteForce) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const test::ReferenceAnswers& ref = test::cached_reference("builtin:spheres?tris=3000", scene.triangles);
    const std::vector<std::map<std::string, std::string>> variants = {
        {{"leaf_size", "1"}}, {{"leaf_size", "16"}}, {{"empty_cut", "1"}}, {{"empty_cut", "0"}}, {{"max_depth", "4"}},
        {{"split", "sah"}}, {{"split", "sah"}, {"leaf_size", "1"}}, {{"split", "sah"}, {"empty_cut", "1"}}};
    for (const auto& params : variants)
        for (const std::string& t : kTraversals) {
            std::string what = "bih " + t;
            for (const auto& [k, v] : params) what += " " + k + "=" + v;
            test::expect_matches(*make_accelerator(scene.triangles, bih(t, params)), ref, what);
        }
}

// Rays lying in, starting on and running just beside the hierarchy's own clip planes.
TEST(Bih, RaysInItsOwnClipPlanes) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const detail::BihTree tree = detail::build_bih(scene.triangles, detail::BihBuildParams{});
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.f, 1.f), s(-1.f, 1.f);
    const Box3 b = tree.bounds;
    std::vector<Ray> rays;
    for (const detail::BihNode& n : tree.nodes) {
        if (n.is_leaf() || rays.size() > 60000) continue;
        for (std::uint32_t side = 0; side < 2; ++side) {
            if (std::isinf(n.clip(side))) continue;
            for (int k = 0; k < 3; ++k) {
                Ray r;
                for (int a = 0; a < 3; ++a) r.org[a] = b.lo[a] + (b.hi[a] - b.lo[a]) * u(rng);
                r.org[n.axis()] = k == 2 ? std::nextafter(n.clip(side), -kInfinity) : n.clip(side);
                r.dir = normalize(Vec3{s(rng), s(rng), s(rng)});
                if (k < 2) r.dir[n.axis()] = k == 0 ? 0.f : -0.f;
                rays.push_back(r);
            }
        }
    }
    const test::ReferenceAnswers ref = test::compute_reference(scene.triangles, rays);
    for (const std::string& t : kTraversals)
        test::expect_matches(*make_accelerator(scene.triangles, bih(t)), ref, "bih " + t + " in clip planes");
}

// Triangles are reordered, not duplicated: every triangle is in exactly one leaf, and the leaves'
// ranges tile the array.
TEST(Bih, LeavesPartitionTheTriangles) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const detail::BihTree tree = detail::build_bih(scene.triangles, detail::BihBuildParams{});
    ASSERT_EQ(tree.triangles.size(), scene.triangles.size());
    std::vector<std::uint32_t> prims = tree.prims;
    std::sort(prims.begin(), prims.end());
    for (std::uint32_t i = 0; i < prims.size(); ++i) ASSERT_EQ(prims[i], i);
    for (std::size_t i = 0; i < tree.triangles.size(); ++i) ASSERT_EQ(tree.triangles[i], scene.triangles[tree.prims[i]]);
    std::vector<int> covered(tree.triangles.size(), 0);
    for (std::size_t i = 2; i < tree.nodes.size(); ++i)
        if (tree.nodes[i].is_leaf())
            for (std::uint32_t k = 0; k < tree.nodes[i].count(); ++k) ++covered[tree.nodes[i].first() + k];
    if (tree.nodes[0].is_leaf()) for (int& c : covered) ++c;
    EXPECT_TRUE(std::all_of(covered.begin(), covered.end(), [](int c) { return c == 1; }));
}

// Spheres of even density, and a city of uneven density whose SAH hierarchy cuts empty space.
TEST(Bih, SameHierarchyBytesAtAnyThreadCount) {
    for (const std::string spec : {"builtin:spheres?tris=40000", "builtin:city?tris=20000"}) {
        const Scene& scene = test::cached_scene(spec);
        for (detail::BihSplit split : {detail::BihSplit::global, detail::BihSplit::sah}) {
            detail::BihBuildParams p;
            p.split = split;
            p.threads = 1;
            const detail::BihTree one = detail::build_bih(scene.triangles, p);
            // Also with the SAH's parallel binning of large nodes brought down to this scene's top nodes.
            for (const std::size_t pass_min : {p.parallel_pass_min, std::size_t{4096}})
                for (unsigned threads : {2u, 3u, 4u, 0u}) {
                    p.threads = threads;
                    p.parallel_pass_min = pass_min;
                    const detail::BihTree many = detail::build_bih(scene.triangles, p);
                    const std::string what =
                        spec + ", " + std::to_string(threads) + " threads, parallel binning from " + std::to_string(pass_min);
                    ASSERT_EQ(one.nodes.size(), many.nodes.size()) << what;
                    EXPECT_EQ(std::memcmp(one.nodes.data(), many.nodes.data(), one.nodes.size() * sizeof(detail::BihNode)), 0)
                        << what;
                    EXPECT_EQ(one.prims, many.prims) << what;
                }
        }
    }
}

// The root's bounds, taken per block of triangles on several threads and combined in block order, are
// one pass's to the bit: where +0 and -0 both bound the scene, the first met is kept (std::min), as
// the tree's clip planes are. Blocks are 16,384 triangles; the two zeros lie in different blocks.
TEST(Bih, RootBoundsKeepTheFirstOfEqualZerosAtAnyThreadCount) {
    for (const bool plus_first : {true, false}) {
        std::vector<Triangle> tris;
        for (int i = 0; i < 40000; ++i) {
            const float x = 1.f + static_cast<float>(i % 200), y = static_cast<float>(i / 200);
            tris.push_back({{x, y, 1.f}, {x + 1.f, y, 1.f}, {x, y + 1.f, 2.f}});
        }
        const float first = plus_first ? 0.f : -0.f, second = plus_first ? -0.f : 0.f;
        tris[10].v0.x = first;
        tris[30000].v1.x = second;
        Box3 expected;
        for (const Triangle& t : tris) expected.extend(t.bounds());
        ASSERT_EQ(std::signbit(expected.lo.x), !plus_first);
        for (unsigned threads : {1u, 2u, 4u}) {
            detail::BihBuildParams p;
            p.split = detail::BihSplit::sah;
            p.threads = threads;
            const detail::BihTree tree = detail::build_bih(tris, p);
            EXPECT_EQ(std::memcmp(&tree.bounds, &expected, sizeof expected), 0) << threads << " threads";
        }
    }
}

// A range partitioned on several threads bounds each side as one ascending pass over its final order
// does: where +0 and -0 both bound the right side, its clip plane keeps the one met first, as the
// one-thread partition's. Two clusters of 20,000 triangles, split at the root between them; the right
// one's lowest x is a zero, given to one triangle as +0 and to another as -0: triangles 2001 (moved
// by the partition to 37,998) and 31001, in different blocks of the partition's passes, or 30001 and
// 30003, in the same block.
TEST(Bih, PartitionOnSeveralThreadsKeepsTheFirstOfEqualZeros) {
    for (const auto& [first, second] : {std::pair{2001, 31001}, std::pair{30001, 30003}}) {
        for (const bool plus_first : {true, false}) {
            std::vector<Triangle> tris;
            for (int i = 0; i < 40000; ++i) {
                const float x = (i % 2 == 1 ? 1.f : -300.f) + static_cast<float>(i / 2 % 100);
                const float y = static_cast<float>(i / 200);
                tris.push_back({{x, y, 1.f}, {x + 1.f, y, 1.f}, {x, y + 1.f, 2.f}});
            }
            tris[first].v0.x = plus_first ? 0.f : -0.f;
            tris[second].v0.x = plus_first ? -0.f : 0.f;
            detail::BihBuildParams p;
            p.split = detail::BihSplit::sah;
            p.threads = 1;
            const detail::BihTree one = detail::build_bih(tris, p);
            ASSERT_FALSE(one.nodes[0].is_leaf());
            ASSERT_EQ(one.nodes[0].axis(), 0);
            ASSERT_EQ(one.nodes[0].clip(1), 0.f);
            p.parallel_pass_min = 4096;
            for (unsigned threads : {2u, 4u}) {
                p.threads = threads;
                const detail::BihTree many = detail::build_bih(tris, p);
                const std::string what = std::to_string(first) + " and " + std::to_string(second) + ", " +
                                         std::to_string(threads) + " threads";
                EXPECT_EQ(std::signbit(many.nodes[0].clip(1)), std::signbit(one.nodes[0].clip(1))) << what;
                ASSERT_EQ(one.nodes.size(), many.nodes.size()) << what;
                EXPECT_EQ(std::memcmp(one.nodes.data(), many.nodes.data(), one.nodes.size() * sizeof(detail::BihNode)), 0)
                    << what;
                EXPECT_EQ(one.prims, many.prims) << what;
            }
        }
    }
}

// The SAH build is a better hierarchy by its own measure: a lower SAH cost in the build report than
// the global heuristic's on a scene of uneven density.
TEST(Bih, SahSplitLowersTheSahCost) {
    const Scene& scene = test::cached_scene("builtin:city?tris=20000");
    auto cost = [&](const std::string& split) {
        const AccelStats s = make_accelerator(scene.triangles, bih("", {{"split", split}}))->stats();
        return s.tree.value().sah_cost;
    };
    EXPECT_LT(cost("sah"), 0.5 * cost("global"));
}

TEST(Bih, ReportsItsBuild) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const AccelStats s = make_accelerator(scene.triangles, bih(""))->stats();
    EXPECT_EQ(s.name, "bih");
    ASSERT_TRUE(s.tree.has_value());
    const TreeReport& t = *s.tree;
    EXPECT_EQ(t.nodes, t.inner_nodes + t.leaves);
    EXPECT_GT(t.leaves, t.empty_leaves);
    ASSERT_TRUE(t.empty_space_nodes.has_value());
    EXPECT_LE(*t.empty_space_nodes, t.inner_nodes);
    EXPECT_GT(t.max_depth, 0);
    EXPECT_LE(t.max_depth, t.depth_limit);
    EXPECT_GT(t.triangles_per_leaf, 0.0);
    EXPECT_DOUBLE_EQ(t.references_per_triangle, 1.0);  // nothing is duplicated
    EXPECT_GT(t.sah_cost, 0.0);
    EXPECT_EQ(s.traversal, "branched");
    EXPECT_EQ(s.setting("split"), "global");
    // The printed report is derived from the typed one.
    const auto figures = s.figures();
    const std::map<std::string, std::string> f(figures.begin(), figures.end());
    EXPECT_EQ(f.at("empty-space nodes"), std::to_string(*t.empty_space_nodes));
    EXPECT_EQ(f.at("nodes"), std::to_string(t.nodes));
    // Memory is known in advance: nodes, the reordered triangles and their scene indices.
    EXPECT_GE(s.memory_bytes, scene.triangles.size() * (sizeof(Triangle) + 4));
}

TEST(Bih, RejectsBadParameters) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=600");
    for (const auto& [k, v] : std::vector<std::pair<std::string, std::string>>{
             {"leaf_size", "0"}, {"max_depth", "65"}, {"empty_cut", "1.5"}, {"bins", "8"}, {"split", "median"}})
        EXPECT_THROW(make_accelerator(scene.triangles, bih("", {{k, v}})), Error) << k << "=" << v;
    EXPECT_THROW(make_accelerator(scene.triangles, bih("rec")), Error);
}

}  // namespace
}  // namespace cellrt
