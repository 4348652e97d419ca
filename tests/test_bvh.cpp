// The wide BVH beyond the checks every structure faces (test_structures.cpp): build variants stay
// exact, the tree's invariants (every triangle in exactly one leaf, every box the exact bounds of
// what lies below it, leaves no larger than asked), the same tree from the same input, rays along
// its own box faces, and an empty scene.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <vector>

#include "accel/routed_accelerator.hpp"
#include "bvh/bvh_accel.hpp"
#include "bvh/bvh_build.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/workload.hpp"
#include "cellrt/error.hpp"
#include "ray_suite.hpp"
#include "scenes.hpp"

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
             {{"traversal_cost", "1000"}}, {{"intersection_cost", "1000"}}}) {
        std::string what = "bvh";
        for (const auto& [k, v] : params) what += " " + k + "=" + v;
        test::expect_matches(*make_accelerator(scene.triangles, bvh(params)), ref, what);
    }
}

// Walks the wide tree: every leaf's lanes name triangles (each exactly once over the tree) whose
// vertices the lanes hold, and every child box is exactly the bounds of the triangles below it.
void check_tree(const BvhTree& tree, std::span<const Triangle> tris, int max_leaf) {
    std::vector<int> seen(tris.size(), 0);
    std::function<Box3(std::uint32_t)> walk = [&](std::uint32_t word) -> Box3 {
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
                const Vec3* v[3] = {&tris[p].v0, &tris[p].v1, &tris[p].v2};
                for (int k = 0; k < 3; ++k)
                    for (int a = 0; a < 3; ++a) EXPECT_EQ(leaf.v[k][a][lane], (*v[k])[static_cast<std::size_t>(a)]);
                bounds.extend(tris[p].bounds());
            }
            return bounds;
        }
        const BvhNode& node = tree.nodes[word];
        for (int k = 0; k < detail::kBvhWidth; ++k) {
            if (node.child[k] == BvhNode::kEmptyChild) {
                EXPECT_GT(node.lo[0][k], node.hi[0][k]) << "an empty slot's box is empty";
                continue;
            }
            const Box3 child = walk(node.child[k]);
            for (int a = 0; a < 3; ++a) {
                EXPECT_EQ(node.lo[a][k], child.lo[a]);
                EXPECT_EQ(node.hi[a][k], child.hi[a]);
            }
            bounds.extend(child);
        }
        return bounds;
    };
    const Box3 root = walk(0);
    EXPECT_EQ(root, tree.bounds);
    for (std::size_t i = 0; i < tris.size(); ++i) EXPECT_EQ(seen[i], 1) << "triangle " << i;
}

TEST(Bvh, EveryTriangleInOneLeafAndEveryBoxExact) {
    for (const char* name : {"builtin:spheres?tris=3000", "builtin:city?tris=5000", "builtin:forest?tris=5000"}) {
        const Scene& scene = test::cached_scene(name);
        for (int max_leaf : {1, 5, 8}) {
            BvhBuildOptions o;
            o.max_leaf = max_leaf;
            SCOPED_TRACE(std::string(name) + " max_leaf " + std::to_string(max_leaf));
            check_tree(detail::build_bvh(scene.triangles, o), scene.triangles, max_leaf);
        }
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
    const Scene& scene = test::cached_scene("builtin:city?tris=5000");
    const BvhTree a = detail::build_bvh(scene.triangles, BvhBuildOptions{});
    const BvhTree b = detail::build_bvh(scene.triangles, BvhBuildOptions{});
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.leaves.size(), b.leaves.size());
    EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)), 0);
    EXPECT_EQ(std::memcmp(a.leaves.data(), b.leaves.data(), a.leaves.size() * sizeof(detail::BvhLeaf)), 0);
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
    test::expect_matches(*make_accelerator(scene.triangles, parse_accel_config("bvh:stream")), ref,
                         "bvh:stream on its box faces");
}

// The stream traversal on batches of every size, from one ray to the whole suite in one call (the
// per-thread scratch grows and is reused), with invalid rays mixed in: the brute-force answers, and
// every ray counted once.
TEST(Bvh, StreamsOfAnySizeMatchBruteForce) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const test::ReferenceAnswers& suite = test::cached_reference("builtin:spheres?tris=3000", scene.triangles);
    std::vector<Ray> rays = suite.rays;
    for (std::size_t i = 0; i < rays.size(); i += 97) rays[i].dir = {0.f, 0.f, 0.f};  // invalid: no hit
    const test::ReferenceAnswers ref = test::compute_reference(scene.triangles, rays);
    const auto stream = make_accelerator(scene.triangles, parse_accel_config("bvh:stream"));
    EXPECT_EQ(stream->stats().traversal, "stream");
    for (std::size_t batch : {std::size_t{1}, std::size_t{7}, std::size_t{256}, std::size_t{1000}, rays.size()}) {
        std::vector<Hit> hits(rays.size());
        std::vector<std::uint8_t> occluded(rays.size(), 2);
        TraversalCounters counters;
        for (std::size_t i = 0; i < rays.size(); i += batch) {
            const std::size_t n = std::min(batch, rays.size() - i);
            stream->intersect(std::span(rays).subspan(i, n), std::span(hits).subspan(i, n), &counters);
            stream->occluded(std::span(rays).subspan(i, n), std::span(occluded).subspan(i, n));
        }
        std::size_t bad = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) bad += !(hits[i] == ref.hits[i]) || occluded[i] != ref.occluded[i];
        EXPECT_EQ(bad, 0u) << "batches of " << batch;
        EXPECT_EQ(counters.rays, rays.size());
        EXPECT_GT(counters.nodes, 0u);
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

TEST(Bvh, RefusesBadParameters) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=200");
    for (const auto& [k, v] : std::vector<std::pair<std::string, std::string>>{
             {"max_leaf", "0"}, {"max_leaf", "9"}, {"bins", "1"}, {"bins", "257"}, {"traversal_cost", "0"},
             {"intersection_cost", "-1"}, {"leaf_size", "4"}})
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

// The measured route: the prior until a sample is in, then the path with the smaller time over the
// samples; every batch sampled while it learns, few once it knows, fewer when the choice is clear.
// How many of the next n batches (coherent by the prior) the picker samples.
int sampled(detail::RoutePicker& p, int n) {
    int s = 0;
    for (int i = 0; i < n; ++i) s += p.pick(0).sampled ? 1 : 0;
    return s;
}

TEST(Routed, PickerTakesThePathThatTookLessTime) {
    using detail::RoutePicker;
    RoutePicker picker;
    for (std::uint64_t i = 0; i < RoutePicker::kPrior; ++i) {  // coherence alone, nothing traced twice
        const RoutePicker::Choice c = picker.pick(static_cast<int>(i % 2));
        EXPECT_EQ(c.path, static_cast<int>(i % 2));
        EXPECT_FALSE(c.sampled);
    }
    const RoutePicker::Choice warm = picker.pick(1);
    EXPECT_EQ(warm.path, 1);
    EXPECT_TRUE(warm.sampled);
    EXPECT_FALSE(warm.counts);
    EXPECT_EQ(picker.pick(0).path, 0);  // nothing recorded yet: the prior
    for (int i = 0; i < 16; ++i) picker.record(2.0, 1.0);
    for (int i = 0; i < 8; ++i) {
        EXPECT_EQ(picker.pick(0).path, 1);
        EXPECT_EQ(picker.pick(1).path, 1);
    }
    // A preempted batch counts at most kClamp times the other path's time: 34 against 16 + 8 * 2 = 32,
    // still the BVH (unclamped, 34 against 56).
    picker.record(2.0, 40.0);
    EXPECT_EQ(picker.pick(0).path, 1);
    for (int i = 0; i < 20; ++i) picker.record(1.0, 3.0);
    EXPECT_EQ(picker.pick(1).path, 0);
}

// With the streams, three paths: the packets and one partner per sample, the partners by turns (the
// single rays and the streams are never timed one after the other on the same rays); each partner's
// cost is its time over the packets' on its own samples, and the route takes the cheapest, sampling
// rarely only when both others are clearly dearer.
TEST(Routed, PickerChoosesAmongThreePaths) {
    using detail::RoutePicker;
    RoutePicker picker(3);
    EXPECT_EQ(picker.paths(), 3);
    for (std::uint64_t i = 0; i <= RoutePicker::kPrior; ++i) EXPECT_EQ(picker.pick(1).path, 1);  // the prior
    int partners[3] = {};
    for (std::uint64_t i = 0; i < RoutePicker::kLearned; ++i) {
        const RoutePicker::Choice c = picker.pick(1);
        ++partners[c.partner];
        // Batches of different sizes: the packets take 3 units, the single rays 2, the streams 1.
        const double size = 1.0 + static_cast<double>(i % 5);
        picker.record(c.partner, 3.0 * size, (c.partner == 1 ? 2.0 : 1.0) * size);
    }
    EXPECT_EQ(partners[1], partners[2]);  // by turns
    EXPECT_NEAR(picker.cost(1), 2.0 / 3.0, 1e-9);
    EXPECT_NEAR(picker.cost(2), 1.0 / 3.0, 1e-9);
    EXPECT_EQ(picker.pick(0).path, 2);
    EXPECT_EQ(picker.pick(1).path, 2);
    // A preempted batch counts at most kClamp times the packets' time.
    const double streams = picker.seconds(2), packets = picker.packet_seconds(2);
    picker.record(2, 1.0, 1000.0);
    EXPECT_EQ(picker.seconds(2) - streams, RoutePicker::kClamp);
    EXPECT_EQ(picker.packet_seconds(2) - packets, 1.0);
    for (int i = 0; i < 40; ++i) picker.record(2, 1.0, 3.0);
    EXPECT_EQ(picker.pick(2).path, 1);  // the streams now dearer than the single rays
    for (int i = 0; i < 400; ++i) picker.record(1, 1.0, 3.0);
    EXPECT_EQ(picker.pick(2).path, 0);  // and both than the packets

    // A partner without samples yet is not chosen, and keeps the choice from being clear.
    RoutePicker half(3);
    for (std::uint64_t i = 0; i < RoutePicker::kPrior; ++i) half.pick(1);
    half.record(1, 3.0, 1.0);
    EXPECT_EQ(half.cost(2), 0.0);
    EXPECT_EQ(half.pick(0).path, 1);
    RoutePicker close(3), clear(3);
    for (std::uint64_t i = 0; i < RoutePicker::kLearned; ++i) {
        close.record(1, 1.0, 3.0);  // the streams close to the packets: sampled often
        close.record(2, 1.0, 1.2);
        clear.record(1, 1.0, 3.0);
        clear.record(2, 1.0, 2.0);
    }
    EXPECT_NEAR(sampled(close, 64000), 64000 / RoutePicker::kSample, 64000 / RoutePicker::kSample / 4);
    EXPECT_NEAR(sampled(clear, 512000), 512000 / RoutePicker::kSampleFar, 512000 / RoutePicker::kSampleFar / 4);
}

TEST(Routed, PickerSamplesFewBatchesOnceItKnows) {
    using detail::RoutePicker;
    RoutePicker learning;
    EXPECT_EQ(sampled(learning, RoutePicker::kPrior), 0);
    EXPECT_NEAR(sampled(learning, 8000), 8000 / RoutePicker::kLearn, 8000 / RoutePicker::kLearn / 4);
    RoutePicker close, clear;
    for (std::uint64_t i = 0; i < RoutePicker::kLearned; ++i) {
        close.record(1.0, 1.2);
        clear.record(1.0, 3.0);
    }
    EXPECT_NEAR(sampled(close, 64000), 64000 / RoutePicker::kSample, 64000 / RoutePicker::kSample / 4);
    EXPECT_NEAR(sampled(clear, 512000), 512000 / RoutePicker::kSampleFar, 512000 / RoutePicker::kSampleFar / 4);
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

// The three paths by name: `auto` holds the streams when told to (not by default: its paired samples
// do not yet choose among three reliably, docs/INCOHERENT.md), and only when it measures.
TEST(Routed, StreamsAreAThirdPathOfTheMeasuredRoute) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=200");
    auto streams = [&](const std::string& spec) {
        return make_accelerator(scene.triangles, parse_accel_config(spec))->stats().setting("streams").value_or("");
    };
    EXPECT_EQ(streams("auto"), "off");
    EXPECT_EQ(streams("auto@streams=on"), "on");
    EXPECT_EQ(streams("auto@streams=on,route=coherence"), "off");
    EXPECT_THROW(make_accelerator(scene.triangles, parse_accel_config("auto@streams=maybe")), Error);
}

// A batch kind the streams trace fastest goes to them: sampled batches are traced by all three paths
// with the same answers, and the work counted is one tracing per ray whichever path answered.
TEST(Routed, StreamedBatchesAnswerAsBruteForce) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=3000");
    const test::ReferenceAnswers& ref = test::cached_reference("builtin:spheres?tris=3000", scene.triangles);
    const auto routed = make_accelerator(scene.triangles, parse_accel_config("auto@streams=on"));
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
}

}  // namespace
}  // namespace cellrt
