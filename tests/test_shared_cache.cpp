// Memory mode (b) of the CUDA backend on the host (docs/GPU.md): the shared-memory software cache
// (cuda/shared_cache.hpp) against the local-store model's software cache (localstore/), the same
// counts for the same reads, read by read and over whole traversals; and the memory parameters'
// validation (cuda/device_memory.hpp), which needs no GPU. That the kernels return the brute-force
// hits through it is DeviceCodeSharedCaches (test_device_code.cpp).
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <type_traits>

#include "accel/local_store_registry.hpp"
#include "accel/structures.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/error.hpp"
#include "cuda/device_memory.hpp"
#include "cuda/device_trace.hpp"
#include "cuda/shared_cache.hpp"
#include "error_of.hpp"
#include "localstore/worker_store.hpp"
#include "ray_suite.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

using detail::CacheAddressMap;
using detail::SharedCache;
using detail::SharedCacheLayout;

// A cache's storage on the host: layout.bytes() bytes, 16-byte aligned.
struct HostCache {
    std::vector<std::uint32_t> words;
    SharedCache cache;
    explicit HostCache(const SharedCacheLayout& layout)
        : words(layout.bytes() / 4), cache(reinterpret_cast<std::byte*>(words.data()), layout) {
        cache.clear(0, 1);
    }
};

void expect_same_counts(const CacheStats& model, const DeviceCacheCounts& shared, const std::string& what) {
    EXPECT_EQ(shared.hits, model.hits) << what;
    EXPECT_EQ(shared.misses, model.misses) << what;
    EXPECT_EQ(shared.evictions, model.evictions) << what;
    EXPECT_EQ(shared.prefetches, model.prefetches) << what;
    EXPECT_EQ(shared.touch_hits, model.touch_hits) << what;
    EXPECT_EQ(shared.torn + shared.unfilled, 0u) << what;
}

const std::vector<SharedCacheLayout> kLayouts = {{16, 64, 1}, {32, 16, 4}, {64, 32, 1}, {64, 8, 4},
                                                 {128, 128, 1}, {256, 4, 4}, {1024, 2, 1}, {4096, 1, 4}};

std::string text(const SharedCacheLayout& l) {
    return std::to_string(l.line_bytes) + "x" + std::to_string(l.sets) + "x" + std::to_string(l.ways);
}

// The same stream of reads (nodes, leaf entries and triangles of a real tree, in runs as a traversal
// makes them) through the model's worker store and the shared-memory cache: the same bytes, and the
// same hits, misses and evictions, for direct-mapped and 4-way caches of lines from 16 B to 4 KiB.
TEST(SharedCache, SameCountsAndBytesAsTheLocalStoresCacheForOneStream) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=2000");
    detail::TreeStructures::for_each([&]<class S>(std::type_identity<S>) {
        AccelConfig config;
        config.kind = S::kName;
        const S s(scene.triangles, config);
        detail::MainMemory memory;
        const std::uint64_t at[3] = {memory.add(s.nodes().data(), s.nodes().size_bytes()),
                                     memory.add(s.entries().data(), s.entries().size_bytes()),
                                     memory.add(s.triangle_array().data(), s.triangle_array().size_bytes())};
        const CacheAddressMap map =
            detail::cache_address_map(s.view(), s.nodes().size(), s.entries().size(), s.triangle_array().size());
        for (int r = 0; r < 3; ++r) ASSERT_EQ(map.base[r], at[r]) << "the model's address of array " << r;
        const std::uint32_t sizes[3] = {sizeof(typename S::Node), 4, sizeof(Triangle)};
        const std::size_t counts[3] = {s.nodes().size(), s.entries().size(), s.triangle_array().size()};
        for (const SharedCacheLayout& layout : kLayouts) {
            LocalStoreConfig c;
            c.node_cache = {layout.line_bytes, layout.sets, layout.ways};
            detail::WorkerStore store(c, memory);
            HostCache shared(layout);
            DeviceCacheCounts got;
            std::mt19937 rng(7);
            std::size_t read = 0;
            for (int run = 0; run < 4000; ++run) {
                // A run of neighbouring objects of one array from a random start, as a descent or a leaf reads them.
                const int r = static_cast<int>(rng() % 3);
                std::size_t k = rng() % counts[r];
                for (int step = static_cast<int>(rng() % 6); step >= 0 && k < counts[r]; --step, k += 1 + rng() % 3) {
                    const std::uint64_t address = at[r] + k * sizes[r];
                    std::uint32_t want[9], have[9];
                    store.read(store.node_cache, address, sizes[r], want);
                    shared.cache.read(map, address, sizes[r], have, got);
                    ASSERT_EQ(std::memcmp(want, have, sizes[r]), 0) << S::kName << " " << text(layout) << " read " << read;
                    ++read;
                }
            }
            expect_same_counts(store.node_cache.stats, got, std::string(S::kName) + " " + text(layout));
            EXPECT_GT(got.hits, 0u);
            EXPECT_GT(got.evictions, 0u) << text(layout);
        }
    });
}

// An address map with `words` as its node array at 4096 and the other two arrays empty.
CacheAddressMap nodes_only(const std::vector<std::uint32_t>& words) {
    CacheAddressMap map{};
    map.data[0] = map.data[1] = map.data[2] = reinterpret_cast<const std::byte*>(words.data());
    for (int r = 0; r < 3; ++r) {
        map.base[r] = r == 0 ? 4096 : 1u << 30;
        map.bytes[r] = r == 0 ? words.size() * 4 : 0;
    }
    return map;
}

// 64 words numbered from `first`: each read's bytes say where they came from.
std::vector<std::uint32_t> numbered(std::uint32_t first) {
    std::vector<std::uint32_t> words(64);
    for (std::size_t i = 0; i < words.size(); ++i) words[i] = first + static_cast<std::uint32_t>(i);
    return words;
}

// Worked by hand: one set of four 16-byte ways, least recently used replacement.
TEST(SharedCache, FourWayLruByHand) {
    const std::vector<std::uint32_t> bytes(1024, 0x5a5a5a5a);
    const CacheAddressMap map = nodes_only(bytes);
    HostCache c({16, 1, 4});  // one set of 4 ways
    DeviceCacheCounts n;
    std::uint32_t out[4];
    auto line = [&](int l) { c.cache.read(map, 4096 + 16 * l, 16, out, n); };
    for (int l : {0, 1, 2, 3}) line(l);  // four misses fill the four ways
    line(0);                             // hit: line 1 is now the least recently used
    line(4);                             // miss, evicts 1
    line(1);                             // miss, evicts 2
    line(0);                             // hit
    EXPECT_EQ(n.misses, 6u);
    EXPECT_EQ(n.hits, 2u);
    EXPECT_EQ(n.evictions, 2u);
    EXPECT_EQ(out[0], 0x5a5a5a5au);
    // A 12-byte object across two 16-byte lines is two lookups.
    const DeviceCacheCounts before = n;
    c.cache.read(map, 4096 + 16 * 6 + 8, 12, out, n);
    EXPECT_EQ(n.lookups() - before.lookups(), 2u);
}

// The seqlock's fall-back, as another thread of a block would trigger it: a line whose sequence
// number is odd (being filled) is neither read nor claimed, and the read takes its bytes from global
// memory, counted unfilled; once the number is even again the line is the cache's.
TEST(SharedCache, ALineBeingFilledIsReadFromGlobalMemory) {
    const std::vector<std::uint32_t> bytes = numbered(1000);
    const CacheAddressMap map = nodes_only(bytes);
    const SharedCacheLayout layout{16, 4, 1};
    HostCache c(layout);
    // The directory follows the lines: tags, then sequence numbers (shared_cache.hpp).
    std::uint32_t& seq0 = c.words[layout.lines() * layout.line_bytes / 4 + layout.lines()];
    DeviceCacheCounts n;
    std::uint32_t out[3];
    c.cache.read(map, 4096 + 4, 12, out, n);  // line 0, slot 0: a miss that fills it
    EXPECT_EQ(seq0, 2u);
    seq0 = 3;  // another thread is filling slot 0
    out[0] = out[1] = out[2] = 0;
    c.cache.read(map, 4096 + 4, 12, out, n);
    EXPECT_EQ(n.misses, 2u);
    EXPECT_EQ(n.unfilled, 1u);
    EXPECT_EQ(n.hits, 0u);
    EXPECT_EQ(out[0], 1001u);
    EXPECT_EQ(out[2], 1003u);
    seq0 = 4;  // it is done, with line 0 still there
    c.cache.read(map, 4096 + 4, 12, out, n);
    EXPECT_EQ(n.hits, 1u);
    EXPECT_EQ(n.lookups(), 3u);
    EXPECT_EQ(n.torn, 0u);
}

// Asynchronous access by hand: a touch claims the line's slot and starts its copy, which stays odd
// (in flight) and unread until the toucher's wait; meanwhile another thread's read does not trust the
// slot and reads global memory; the wait publishes the line, whose bytes the next read finds; and a
// touch of a line already there is a touch hit.
TEST(SharedCache, ATouchedLineIsInFlightUntilTheWait) {
    const std::vector<std::uint32_t> bytes = numbered(2000);
    const CacheAddressMap map = nodes_only(bytes);
    const SharedCacheLayout layout{32, 4, 1};
    HostCache c(layout);
    const std::uint32_t* line0 = c.words.data();
    const std::uint32_t& seq0 = c.words[layout.lines() * layout.line_bytes / 4 + layout.lines()];
    detail::AsyncFills fills;
    DeviceCacheCounts mine, other;
    c.cache.touch(map, 4096 + 16, 24, fills, mine);  // lines 0 and 1: two prefetches
    EXPECT_EQ(mine.prefetches, 2u);
    EXPECT_EQ(fills.count, 2);
    EXPECT_EQ(seq0, 1u);
    EXPECT_EQ(line0[2], 0u);  // not arrived: the host makes the copy at the wait
    std::uint32_t out[2] = {};
    c.cache.read(map, 4096 + 8, 8, out, other);  // another thread: the slot is in flight
    EXPECT_EQ(other.hits, 0u);
    EXPECT_EQ(other.unfilled, 1u);
    EXPECT_EQ(out[0], 2002u);
    c.cache.complete(map, fills);
    EXPECT_EQ(fills.count, 0);
    EXPECT_EQ(seq0, 2u);
    EXPECT_EQ(line0[2], 2002u);
    out[0] = out[1] = 0;
    c.cache.read(map, 4096 + 40, 8, out, mine);  // line 1, published by the same wait
    EXPECT_EQ(mine.hits, 1u);
    EXPECT_EQ(out[1], 2011u);
    c.cache.touch(map, 4096, 4, fills, mine);
    EXPECT_EQ(mine.touch_hits, 1u);
    EXPECT_EQ(fills.count, 0);
    EXPECT_EQ(mine.misses + mine.evictions, 0u);
}

// Whole traversals: one worker of the model and the policy of mode (b) on the host, tracing the same
// rays in the same order over the same tree, count the same hits, misses and evictions in the node
// cache (nodes and leaf entries) and in the triangle cache, and with asynchronous access the same
// prefetches and touch hits, for every tree and traversal: the GPU's caches, one thread at a time,
// are the study's, in both access modes (the model's asynchronous access with its re-touch).
TEST(SharedCache, SameCountsAsTheLocalStoreModelOverWholeTraversals) {
    const std::string name = "builtin:city?tris=20000";
    const Scene& scene = test::cached_scene(name);
    const std::vector<Ray>& all = test::cached_reference(name, scene.triangles).rays;
    const std::span<const Ray> rays = std::span(all).first(std::min<std::size_t>(all.size(), 6000));
    const std::pair<SharedCacheLayout, SharedCacheLayout> layouts[] = {{{64, 64, 1}, {128, 32, 1}},
                                                                       {{32, 32, 4}, {64, 16, 4}}};
    detail::TreeStructures::for_each([&]<class S>(std::type_identity<S>) {
        AccelConfig config;
        config.kind = S::kName;
        const S s(scene.triangles, config);
        using Traits = typename S::Traits;
        for (const auto& t : S::kTraversals) {
            for (const auto& [nodes, triangles] : layouts)
              for (const CacheAccess access : {CacheAccess::sync, CacheAccess::async}) {
                const std::string what = std::string(S::kName) + ":" + t.name + " " + text(nodes) + " " + text(triangles) +
                                         " " + to_string(access);
                LocalStoreConfig c;
                c.node_cache = {nodes.line_bytes, nodes.sets, nodes.ways};
                c.triangle_cache = {triangles.line_bytes, triangles.sets, triangles.ways};
                c.access = access;
                config.traversal = t.name;
                const auto model = make_local_store_accelerator(scene.triangles, config, c);
                std::vector<Hit> want(rays.size()), got(rays.size());
                model->intersect(rays, want);
                const LocalStoreStats m = model->local_store_stats();

                HostCache node_cache(nodes), triangle_cache(triangles);
                const auto view = s.view();
                const CacheAddressMap map = detail::cache_address_map(view, s.nodes().size(), s.entries().size(),
                                                                      s.triangle_array().size());
                detail::SharedCacheMemory<typename Traits::Node> mem(node_cache.cache, triangle_cache.cache, map,
                                                                     access == CacheAccess::async);
                detail::RayCounters count;
                S::with_kernel(t.value, [&](auto kernel) {
                    for (std::size_t i = 0; i < rays.size(); ++i)
                        got[i] = detail::trace_closest<Traits, decltype(kernel)>(view, mem, rays[i], count);
                });
                EXPECT_TRUE(got == want) << what;
                expect_same_counts(m.node_cache, mem.node_counts, what + " node cache");
                expect_same_counts(m.triangle_cache, mem.triangle_counts, what + " triangle cache");
                EXPECT_GT(mem.node_counts.evictions, 0u) << what;
                EXPECT_GT(mem.triangle_counts.hits, 0u) << what;
                if (access == CacheAccess::async) {
                    EXPECT_GT(mem.node_counts.prefetches, 0u) << what;
                }
              }
        }
    });
}

AccelConfig with_params(std::map<std::string, std::string> params) {
    AccelConfig c;
    c.params = std::move(params);
    return c;
}

TEST(DeviceMemoryParams, DefaultIsGlobalMemoryAndSharedTakesTheLayouts) {
    EXPECT_FALSE(detail::read_device_memory(AccelConfig{}).shared);
    EXPECT_FALSE(detail::read_device_memory(with_params({{"memory", "shared"}})).async);
    const detail::DeviceMemoryConfig a = detail::read_device_memory(with_params({{"memory", "shared"}, {"access", "async"}}));
    EXPECT_TRUE(a.async);
    EXPECT_EQ(a.to_string(), "shared: node cache 128x128, triangle cache 128x128, " + std::to_string(a.shared_bytes()) +
                                 " B a block, asynchronous access");
    const detail::DeviceMemoryConfig m = detail::read_device_memory(with_params(
        {{"memory", "shared"}, {"node_line", "64"}, {"node_sets", "256"}, {"node_ways", "4"}, {"triangle_line", "32"}}));
    EXPECT_TRUE(m.shared);
    EXPECT_EQ(m.node_cache.line_bytes, 64u);
    EXPECT_EQ(m.node_cache.sets, 256u);
    EXPECT_EQ(m.node_cache.ways, 4u);
    EXPECT_EQ(m.triangle_cache.line_bytes, 32u);
    EXPECT_EQ(m.triangle_cache.sets, 128u);
    EXPECT_EQ(m.triangle_cache.ways, 1u);
    // 64 x 256 x 4 lines of 64 B plus 12 B of directory each, and the clock; 32 x 128 lines of 32 + 12 B.
    EXPECT_EQ(m.node_cache.bytes(), (1024u * 76 + 4 + 15) / 16 * 16);
    EXPECT_EQ(m.shared_bytes(), m.node_cache.bytes() + (128u * 44 + 4 + 15) / 16 * 16);
    EXPECT_EQ(m.to_string(), "shared: node cache 64x256x4, triangle cache 32x128, " + std::to_string(m.shared_bytes()) +
                                 " B a block");
    // The tree's own parameters pass to the tree, the memory's do not.
    const AccelConfig rest = detail::without_device_memory(with_params({{"memory", "shared"}, {"leaf_size", "3"}}));
    EXPECT_EQ(rest.params, (std::map<std::string, std::string>{{"leaf_size", "3"}}));
}

TEST(DeviceMemoryParams, BadLayoutsAreRefusedInOneLine) {
    auto error = [](std::map<std::string, std::string> p) {
        p.emplace("memory", "shared");
        return test::error_of([&] { detail::read_device_memory(with_params(p)); });
    };
    EXPECT_EQ(error({{"node_line", "48"}}), "cuda parameter node_line=48: a line is a power of two bytes");
    EXPECT_EQ(error({{"triangle_sets", "96"}}), "cuda parameter triangle_sets=96: the number of sets is a power of two");
    EXPECT_EQ(error({{"node_line", "8"}}), "cuda parameter node_line=8 is out of range [16, 4096]");
    EXPECT_EQ(error({{"node_line", "8192"}}), "cuda parameter node_line=8192 is out of range [16, 4096]");
    EXPECT_NE(error({{"node_ways", "2"}}).find("node_ways"), std::string::npos);
    EXPECT_NE(error({{"memory", "texture"}}).find("memory"), std::string::npos);
    EXPECT_EQ(test::error_of([] { detail::read_device_memory(with_params({{"node_line", "64"}})); }),
              "cuda parameter node_line=64 shapes the shared-memory caches: it needs memory=shared");
    EXPECT_EQ(test::error_of([] { detail::read_device_memory(with_params({{"access", "async"}})); }),
              "cuda parameter access=async shapes the shared-memory caches: it needs memory=shared");
    EXPECT_NE(error({{"access", "dma"}}).find("access"), std::string::npos);
}

TEST(DeviceMemoryParams, CachesOverTheBlocksSharedMemoryAreRefused) {
    detail::DeviceMemoryConfig m;
    m.shared = true;
    m.node_cache = {256, 512, 1};  // 128 KiB of lines
    m.triangle_cache = {128, 1024, 1};  // 128 KiB
    const std::size_t h200 = 232448;  // cudaDevAttrMaxSharedMemoryPerBlockOptin of an H100/H200: 227 KiB
    EXPECT_EQ(test::error_of([&] { detail::check_shared_memory(m, h200, 1 << 20); }),
              "the shared-memory caches (node cache 256x512: 137232 B, triangle cache 128x1024: 143376 B, with their "
              "directories) need 280608 B, over the 232448 B of shared memory a block of this device has");
    m.triangle_cache = {128, 512, 1};
    EXPECT_EQ(test::error_of([&] { detail::check_shared_memory(m, h200, 1 << 20); }), "no error");
    EXPECT_NE(test::error_of([&] { detail::check_shared_memory(m, h200, std::uint64_t(1) << 36); }), "no error");
    m.shared = false;
    EXPECT_EQ(test::error_of([&] { detail::check_shared_memory(m, 0, 1 << 20); }), "no error");
}

}  // namespace
}  // namespace cellrt
