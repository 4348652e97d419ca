// The CUDA backend's device code, compiled for the host (CELLRT_HD is empty here) and held to brute
// force bit for bit: what each GPU thread runs for one ray (cuda/device_trace.hpp), every tree of the
// registry's list and every traversal, over the tree packed as the backend copies it to the device
// (cuda/device_tree.hpp), on the built-in and shared scenes and the degenerate inputs. Runs with or
// without CUDA and a GPU: CI has neither (docs/GPU.md).
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <type_traits>

#include "accel/structures.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/render.hpp"
#include "cellrt/workload.hpp"
#include "cuda/device_frame.hpp"
#include "cuda/device_memory.hpp"
#include "cuda/device_trace.hpp"
#include "cuda/device_tree.hpp"
#include "cuda/shared_cache.hpp"
#include "ray_suite.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

// A tree packed into one 16-byte aligned buffer and traced ray by ray with the device's per-thread
// functions, behind the accelerator boundary so that the suite's comparison applies as it is: in
// global memory (mode (a)), or with `memory.shared` through a block's shared-memory caches (mode (b),
// cuda/shared_cache.hpp), here a host array emptied at each call as a block's are at each launch.
class CacheTracer : public Accelerator {
public:
    virtual DeviceCacheStats caches() const = 0;  // mode (b): the caches' counts over every call so far
    // The GPU frame path's threads, one pixel after another: the window's pixels, row-major, with
    // the work of the primary rays and of every other ray added to the two counters.
    virtual void render(const FrameShading& frame, std::span<const Triangle> triangles, const detail::FrameWindow& window,
                        std::span<Vec3> pixels, TraversalCounters& primary, TraversalCounters& secondary) const = 0;
};

template <class S, class Kernel>
class PackedTracer final : public CacheTracer {
public:
    using Traits = typename S::Traits;
    explicit PackedTracer(const S& s, const detail::DeviceMemoryConfig& memory = {})
        : memory_(memory),
          layout_(detail::packed_layout<Traits>(s.nodes().size(), s.entries().size(), s.triangle_array().size(),
                                                s.bounds())),
          bytes_(static_cast<std::byte*>(::operator new(layout_.bytes, std::align_val_t{detail::kPackedAlignment}))) {
        detail::pack_tree<Traits>(s.nodes(), s.entries(), s.triangle_array(), layout_, bytes_.get());
    }
    AccelStats stats() const override { return {}; }
    DeviceCacheStats caches() const override {
        const std::lock_guard lock(mutex_);
        return cache_stats_;
    }

    void render(const FrameShading& frame, std::span<const Triangle> triangles, const detail::FrameWindow& window,
                std::span<Vec3> pixels, TraversalCounters& primary, TraversalCounters& secondary) const override {
        with_memory([&](const auto& view, auto& mem) {
            detail::PixelCounters c;
            for (int y = 0; y < window.height; ++y)
                for (int x = 0; x < window.width; ++x)
                    pixels[static_cast<std::size_t>(y * window.width + x)] = detail::render_pixel<Traits, Kernel>(
                        view, mem, frame, triangles.data(), window.x0 + x, window.y0 + y, c);
            add(c.primary, static_cast<std::size_t>(window.width * window.height), &primary);
            add(c.secondary, c.secondary_rays, &secondary);
        });
    }

private:
    struct Free {
        void operator()(std::byte* p) const { ::operator delete(p, std::align_val_t{detail::kPackedAlignment}); }
    };
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        with_memory([&](const auto& view, auto& mem) {
            detail::RayCounters c;
            for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = detail::trace_closest<Traits, Kernel>(view, mem, rays[i], c);
            add(c, rays.size(), counters);
        });
    }
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        with_memory([&](const auto& view, auto& mem) {
            detail::RayCounters c;
            for (std::size_t i = 0; i < rays.size(); ++i)
                occluded[i] = detail::trace_any<Traits, Kernel>(view, mem, rays[i], c) ? 1 : 0;
            add(c, rays.size(), counters);
        });
    }
    // Calls fn(view, memory policy) with the policy of the memory mode.
    template <class Fn>
    void with_memory(Fn&& fn) const {
        const auto view = detail::packed_view<Traits>(bytes_.get(), layout_);
        if (!memory_.shared) {
            auto mem = view.memory();
            fn(view, mem);
            return;
        }
        std::vector<std::uint32_t> storage(memory_.shared_bytes() / 4);
        auto* at = reinterpret_cast<std::byte*>(storage.data());
        const detail::SharedCache nodes(at, memory_.node_cache), triangles(at + memory_.node_cache.bytes(),
                                                                          memory_.triangle_cache);
        nodes.clear(0, 1);
        triangles.clear(0, 1);
        const detail::CacheAddressMap map =
            detail::cache_address_map(view, layout_.nodes, layout_.entries, layout_.triangles);
        detail::SharedCacheMemory<typename Traits::Node> mem(nodes, triangles, map, memory_.async);
        fn(view, mem);
        const std::lock_guard lock(mutex_);
        cache_stats_.node_cache += mem.node_counts;
        cache_stats_.triangle_cache += mem.triangle_counts;
        ++cache_stats_.blocks;
    }
    static void add(const detail::RayCounters& c, std::size_t rays, TraversalCounters* counters) {
        if (!counters) return;
        counters->rays += rays;
        counters->nodes += c.nodes;
        counters->leaves += c.leaves;
        counters->triangles += c.triangles;
    }

    detail::DeviceMemoryConfig memory_;
    detail::PackedTree layout_;
    std::unique_ptr<std::byte, Free> bytes_;
    mutable std::mutex mutex_;
    mutable DeviceCacheStats cache_stats_;
};

// The host's own closest-hit batch loop over a tree's own arrays, as its single-ray accelerator runs it.
using HostPath = std::function<void(std::span<const Ray>, std::span<Hit>, TraversalCounters*)>;

// Calls check(name, tracer, host) for every listed tree and traversal, the tree built over `tris` as
// the host's single-ray path builds it, the tracer reading it in `memory`'s mode.
template <class Check>
void for_every_device_kernel(std::span<const Triangle> tris, Check&& check, const detail::DeviceMemoryConfig& memory = {}) {
    detail::TreeStructures::for_each([&]<class S>(std::type_identity<S>) {
        AccelConfig config;
        config.kind = S::kName;
        const S s(tris, config);
        for (const auto& t : S::kTraversals) {
            S::with_kernel(t.value, [&](auto kernel) {
                const PackedTracer<S, decltype(kernel)> tracer(s, memory);
                const HostPath host = [&](std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* c) {
                    auto mem = s.view().memory();
                    detail::closest_hits(s.bounds(), rays, hits, c, [&](const detail::TraversalRay& r, auto& q,
                                                                         auto& count) {
                        return kernel(s.tree, mem, r, q, count);
                    });
                };
                check(std::string(S::kName) + ":" + t.name, tracer, host);
            });
        }
    });
}

class DeviceCode : public testing::TestWithParam<std::string> {};

// Same hits as brute force, and the same work counts as the host's own single-ray path: the device
// runs the same kernel over the same tree.
TEST_P(DeviceCode, SameHitsAndWorkAsTheHost) {
    const Scene* scene = test::structure_scene(GetParam());
    if (!scene) GTEST_SKIP() << "scene " << GetParam() << " not found under " << test::scenes_dir();
    const test::ReferenceAnswers& ref = test::cached_reference(GetParam(), scene->triangles);
    for_every_device_kernel(scene->triangles, [&](const std::string& name, const Accelerator& tracer,
                                                  const HostPath& host_path) {
        test::expect_matches(tracer, ref, "device code " + name + " on " + GetParam());
        const std::span<const Ray> some = std::span(ref.rays).first(std::min<std::size_t>(ref.rays.size(), 20000));
        std::vector<Hit> hits(some.size());
        TraversalCounters device, host;
        tracer.intersect(some, hits, &device);
        host_path(some, hits, &host);
        EXPECT_GT(host.triangles, 0u) << name;
        EXPECT_EQ(device.nodes, host.nodes) << name;
        EXPECT_EQ(device.leaves, host.leaves) << name;
        EXPECT_EQ(device.triangles, host.triangles) << name;
    });
}

INSTANTIATE_TEST_SUITE_P(Scenes, DeviceCode, testing::ValuesIn(test::structure_scene_names()),
                         [](const auto& info) { return test::test_name(info.param); });

// Memory mode (b) on the host: small caches, so that lines are evicted all the time and objects
// straddle lines (12-byte BIH nodes in 32-byte lines, 36-byte triangles in 64-byte ones); with
// `async`, the study's asynchronous access (touch, then wait).
detail::DeviceMemoryConfig small_shared_caches(bool async = false) {
    detail::DeviceMemoryConfig m;
    m.shared = true;
    m.async = async;
    m.node_cache = {32, 64, 4};
    m.triangle_cache = {64, 32, 1};
    return m;
}

class DeviceCodeSharedCaches : public testing::TestWithParam<std::string> {};

// Through the block's software caches the kernels read the same bytes, so they return the
// brute-force hits and do the host's work exactly; every lookup is counted, and on the host (one
// thread a cache) none is torn or unfilled.
TEST_P(DeviceCodeSharedCaches, SameHitsAndWorkAsTheHost) {
    const Scene* scene = test::structure_scene(GetParam());
    if (!scene) GTEST_SKIP() << "scene " << GetParam() << " not found under " << test::scenes_dir();
    const test::ReferenceAnswers& ref = test::cached_reference(GetParam(), scene->triangles);
    for_every_device_kernel(
        scene->triangles,
        [&](const std::string& name, const Accelerator& tracer, const HostPath& host_path) {
            test::expect_matches(tracer, ref, "shared-memory caches " + name + " on " + GetParam());
            const std::span<const Ray> some = std::span(ref.rays).first(std::min<std::size_t>(ref.rays.size(), 20000));
            std::vector<Hit> hits(some.size());
            TraversalCounters device, host;
            const DeviceCacheStats before = dynamic_cast<const CacheTracer&>(tracer).caches();
            tracer.intersect(some, hits, &device);
            const DeviceCacheStats after = dynamic_cast<const CacheTracer&>(tracer).caches();
            host_path(some, hits, &host);
            EXPECT_GT(host.triangles, 0u) << name;
            EXPECT_EQ(device.nodes, host.nodes) << name;
            EXPECT_EQ(device.leaves, host.leaves) << name;
            EXPECT_EQ(device.triangles, host.triangles) << name;
            const DeviceCacheCounts& n = after.node_cache;
            const DeviceCacheCounts& t = after.triangle_cache;
            // At least one node lookup per node visited and leaf reached, one triangle lookup per test.
            EXPECT_GE(n.lookups() - before.node_cache.lookups(), host.nodes + host.leaves) << name;
            EXPECT_GE(t.lookups() - before.triangle_cache.lookups(), host.triangles) << name;
            EXPECT_GT(n.hits, 0u) << name;
            EXPECT_GT(n.evictions, 0u) << name;
            EXPECT_EQ(n.torn + n.unfilled + t.torn + t.unfilled, 0u) << name;
        },
        small_shared_caches());
}

INSTANTIATE_TEST_SUITE_P(Scenes, DeviceCodeSharedCaches, testing::ValuesIn(test::structure_scene_names()),
                         [](const auto& info) { return test::test_name(info.param); });

class DeviceFrame : public testing::TestWithParam<std::string> {};

// The GPU's frame path as each of its threads runs it (cuda/device_frame.hpp: a pixel's rays made,
// traced through the packed tree and shaded), pixel after pixel on the host, gives the CPU renderer's
// image bit for bit, for every tree and traversal, in both memory modes, under the three shadings,
// for the whole frame and for a window of it (a distributed frame's tile); and it casts as many rays
// as the renderer. The frame's sides are no multiple of the packets' or the GPU's 8 x 4 tiles.
TEST_P(DeviceFrame, SameImageAsTheRenderer) {
    const Scene* scene = test::structure_scene(GetParam());
    if (!scene) GTEST_SKIP() << "scene " << GetParam() << " not found under " << test::scenes_dir();
    constexpr int kWidth = 45, kHeight = 38;
    const PixelRect window{7, 5, 30, 28};
    const auto cpu = make_accelerator(scene->triangles, parse_accel_config("kd"));
    struct Expected {
        ShadingOptions shading;
        Image image;
        std::uint64_t secondary_rays;
    };
    std::vector<Expected> expected;
    for (const ShadingOptions shading : {ShadingOptions{Shading::direct, 4}, ShadingOptions{Shading::ao, 3},
                                         ShadingOptions{Shading::diffuse, 4}}) {
        RenderOptions ro;
        ro.width = kWidth;
        ro.height = kHeight;
        ro.threads = 2;
        ro.packet = 8;
        ro.shading = shading;
        RenderStats stats;
        Image image = cellrt::render(*scene, *cpu, ro, &stats);
        expected.push_back({shading, std::move(image), stats.secondary_rays});
    }
    const PinholeCamera camera(scene->camera, kWidth, kHeight);
    const auto same_bits = [](const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    for (const detail::DeviceMemoryConfig& memory :
         {detail::DeviceMemoryConfig{}, small_shared_caches(), small_shared_caches(true)})
        for_every_device_kernel(
            scene->triangles,
            [&](const std::string& name, const Accelerator& tracer, const HostPath&) {
                const auto& device = dynamic_cast<const CacheTracer&>(tracer);
                for (const Expected& e : expected) {
                    const std::string what = name + (memory.shared ? memory.async ? " (shared caches, async), "
                                                                                  : " (shared caches), "
                                                                   : ", ") +
                                             to_string(e.shading.shading) + " on " + GetParam();
                    const FrameShading frame = frame_shading(*scene, camera, e.shading);
                    std::vector<Vec3> pixels(static_cast<std::size_t>(kWidth * kHeight));
                    TraversalCounters primary, secondary;
                    device.render(frame, scene->triangles, {0, 0, kWidth, kHeight}, pixels, primary, secondary);
                    int differ = 0;
                    for (int y = 0; y < kHeight; ++y)
                        for (int x = 0; x < kWidth; ++x)
                            differ += !same_bits(pixels[static_cast<std::size_t>(y * kWidth + x)], e.image.at(x, y));
                    EXPECT_EQ(differ, 0) << what;
                    EXPECT_EQ(primary.rays, static_cast<std::uint64_t>(kWidth * kHeight)) << what;
                    EXPECT_EQ(secondary.rays, e.secondary_rays) << what;
                    EXPECT_GT(secondary.rays, 0u) << what;

                    std::vector<Vec3> tile(static_cast<std::size_t>(window.pixels()));
                    TraversalCounters unused_primary, unused_secondary;
                    device.render(frame, scene->triangles, {window.x0, window.y0, window.width(), window.height()}, tile,
                                  unused_primary, unused_secondary);
                    differ = 0;
                    for (int y = 0; y < window.height(); ++y)
                        for (int x = 0; x < window.width(); ++x)
                            differ += !same_bits(tile[static_cast<std::size_t>(y * window.width() + x)],
                                                 e.image.at(window.x0 + x, window.y0 + y));
                    EXPECT_EQ(differ, 0) << what << ", window";
                }
            },
            memory);
}

INSTANTIATE_TEST_SUITE_P(Scenes, DeviceFrame, testing::ValuesIn(test::structure_scene_names()),
                         [](const auto& info) { return test::test_name(info.param); });

// Through the shared-memory caches, every thirteenth ray and the invalid ones (the sanitized
// stages' sample, in every build): the caches change where a kernel's bytes come from, not its
// arithmetic, and DeviceCodeSharedCaches puts every ray of the scenes through them. Every ray in
// global memory. (In Release the whole suite through both cache modes took 35 of this test's 48 s,
// most of it the 1,000 duplicates, each ray testing all of them.)
TEST(DeviceCodeDegenerate, SameHitsAsBruteForce) {
    for (const auto& [what, tris] : test::degenerate_scenes()) {
        const test::ReferenceAnswers ref = test::reference_suite(tris, test::small_suite());
        const test::ReferenceAnswers sample = test::sanitized_sample(ref, test::kSanitizedSampleStride);
        for_every_device_kernel(tris, [&](const std::string& name, const Accelerator& tracer, const HostPath&) {
            test::expect_matches(tracer, ref, "device code " + name + " on " + what);
        });
        for (const bool async : {false, true})
            for_every_device_kernel(
                tris,
                [&](const std::string& name, const Accelerator& tracer, const HostPath&) {
                    test::detail::expect_all_match(tracer, sample,
                                                   "shared-memory caches " + name + (async ? " async" : "") + " on " + what);
                },
                small_shared_caches(async));
    }
}

TEST(DeviceCodeDegenerate, EmptySceneMissesEverything) {
    const std::vector<Triangle> none;
    const std::vector<Ray> rays = {{{0.f, 0.f, 0.f}, 0.f, {1.f, 0.f, 0.f}, kInfinity}};
    for_every_device_kernel(none, [&](const std::string& name, const Accelerator& tracer, const HostPath&) {
        std::vector<Hit> hits(1);
        std::vector<std::uint8_t> occluded(1, 2);
        tracer.intersect(rays, hits);
        tracer.occluded(rays, occluded);
        EXPECT_FALSE(hits[0].is_hit()) << name;
        EXPECT_EQ(occluded[0], 0) << name;
    });
}

// The packed layout: every array at a 16-byte boundary, in order, nothing overlapping.
TEST(DevicePackedTree, ArraysAlignedAndDisjoint) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=2000");
    detail::TreeStructures::for_each([&]<class S>(std::type_identity<S>) {
        AccelConfig config;
        config.kind = S::kName;
        const S s(scene.triangles, config);
        const auto p = detail::packed_layout<typename S::Traits>(s.nodes().size(), s.entries().size(),
                                                                 s.triangle_array().size(), s.bounds());
        EXPECT_EQ(p.entries_offset % detail::kPackedAlignment, 0u);
        EXPECT_EQ(p.triangles_offset % detail::kPackedAlignment, 0u);
        EXPECT_GE(p.entries_offset, s.nodes().size_bytes());
        EXPECT_GE(p.triangles_offset, p.entries_offset + s.entries().size_bytes());
        EXPECT_GE(p.bytes, p.triangles_offset + s.triangle_array().size_bytes());
        EXPECT_LT(p.bytes, p.triangles_offset + s.triangle_array().size_bytes() + detail::kPackedAlignment);
    });
}

}  // namespace
}  // namespace cellrt
