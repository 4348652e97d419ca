// The packet scheduler: every dispatch mode, worker count and packet size gives the same image.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "cellrt/timer.hpp"
#include "scenes.hpp"
#include "schedule/worker_team.hpp"

namespace cellrt {
namespace {

bool same_bits(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Vec3)) == 0;
}

Image render_scene(const Scene& scene, const Accelerator& accel, int w, int h, Dispatch d, unsigned workers, int packet) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.dispatch = d;
    o.threads = workers;
    o.packet = packet;
    return render(scene, accel, o);
}

TEST(Schedule, SameImageForEveryDispatchWorkerCountAndPacketSize) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=400");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"brute"});
    // 37 x 29 is a multiple of no packet size > 1: edge packets are partial.
    const Image reference = render_scene(scene, *accel, 37, 29, Dispatch::pull, 1, 1);
    for (Dispatch d : {Dispatch::pull, Dispatch::mailbox})
        for (unsigned workers : {1u, 2u, 3u, 6u})
            for (int packet : {1, 2, 4, 8, 16})
                EXPECT_TRUE(same_bits(render_scene(scene, *accel, 37, 29, d, workers, packet), reference))
                    << to_string(d) << " workers " << workers << " packet " << packet;
}

TEST(Schedule, MoreWorkersThanPackets) {
    const Scene& scene = test::cached_scene("builtin:spheres?tris=400");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"brute"});
    const Image reference = render_scene(scene, *accel, 10, 6, Dispatch::pull, 1, 4);
    for (Dispatch d : {Dispatch::pull, Dispatch::mailbox})
        EXPECT_TRUE(same_bits(render_scene(scene, *accel, 10, 6, d, 8, 16), reference)) << to_string(d);
}

TEST(Schedule, EveryPixelIsWrittenOnce) {
    const PacketGrid grid(23, 17, 8);
    Image image(23, 17);
    for (Dispatch d : {Dispatch::pull, Dispatch::mailbox}) {
        std::fill(image.pixels.begin(), image.pixels.end(), Vec3{});
        ScheduleOptions o;
        o.dispatch = d;
        o.workers = 3;
        ASSERT_TRUE(run_packets(grid, o, image, [](unsigned, const PixelRect& r, std::span<Vec3> out) {
            ASSERT_EQ(out.size(), static_cast<std::size_t>(r.pixels()));
            for (int y = r.y0; y < r.y1; ++y)
                for (int x = r.x0; x < r.x1; ++x)
                    out[static_cast<std::size_t>(y - r.y0) * r.width() + (x - r.x0)] = Vec3{float(x), float(y), 1.f};
        }));
        for (int y = 0; y < 17; ++y)
            for (int x = 0; x < 23; ++x) ASSERT_EQ(image.at(x, y), (Vec3{float(x), float(y), 1.f})) << to_string(d);
    }
}

// Each worker's load names the packets that worker traced, and its busy time covers the time they
// took (each packet here takes at least 200 microseconds).
TEST(Schedule, ReportsEachWorkersLoad) {
    const PacketGrid grid(40, 24, 8);
    Image image(40, 24);
    for (Dispatch d : {Dispatch::pull, Dispatch::mailbox}) {
        constexpr unsigned kWorkers = 3;
        std::array<std::atomic<std::size_t>, kWorkers> traced{};
        ScheduleOptions o;
        o.dispatch = d;
        o.workers = kWorkers;
        std::vector<WorkerLoad> loads;
        ASSERT_TRUE(run_packets(
            grid, o, image,
            [&](unsigned w, const PixelRect&, std::span<Vec3>) {
                ++traced[w];
                const Timer t;
                while (t.seconds() < 200e-6) {}
            },
            &loads));
        ASSERT_EQ(loads.size(), kWorkers) << to_string(d);
        std::size_t packets = 0;
        for (unsigned w = 0; w < kWorkers; ++w) {
            EXPECT_EQ(loads[w].packets, traced[w].load()) << to_string(d) << " worker " << w;
            EXPECT_GE(loads[w].busy_seconds, 200e-6 * static_cast<double>(loads[w].packets)) << to_string(d);
            packets += loads[w].packets;
        }
        EXPECT_EQ(packets, grid.count()) << to_string(d);
    }
}

TEST(Schedule, CancellationStopsEarlyAndReportsIt) {
    const PacketGrid grid(64, 64, 2);
    Image image(64, 64);
    for (Dispatch d : {Dispatch::pull, Dispatch::mailbox}) {
        std::atomic<bool> cancel{false};
        std::atomic<std::size_t> traced{0};
        ScheduleOptions o;
        o.dispatch = d;
        o.workers = 2;
        o.cancel = &cancel;
        o.progress = [&](std::size_t done, std::size_t) {
            if (done == 10) cancel = true;
        };
        EXPECT_FALSE(run_packets(grid, o, image, [&](unsigned, const PixelRect&, std::span<Vec3>) { ++traced; }));
        EXPECT_LT(traced.load(), grid.count() / 2) << to_string(d);
    }
}

TEST(Schedule, RejectsBadSettings) {
    EXPECT_THROW(PacketGrid(16, 16, 0), Error);
    EXPECT_THROW(parse_dispatch("push"), Error);
    EXPECT_EQ(parse_dispatch("mailbox"), Dispatch::mailbox);
}

// The team behind both dispatch modes: every worker index runs once per run, all at the same time
// (a job that waits for all the others would hang otherwise), worker w on the same thread from run
// to run, the caller's `meanwhile` alongside, and a larger run after a smaller one grows the team.
TEST(WorkerTeam, RunsEveryWorkerAtOnceOnKeptThreads) {
    detail::WorkerTeam team;
    std::vector<std::thread::id> first(4);
    for (unsigned n : {4u, 2u, 4u, 6u}) {
        std::atomic<unsigned> arrived{0};
        std::mutex m;
        std::vector<std::thread::id> ids(n);
        std::set<std::thread::id> distinct;
        bool meanwhile_ran = false;
        team.run(
            n, false,
            [&](unsigned w) {
                arrived.fetch_add(1);
                while (arrived.load() < n) std::this_thread::yield();  // a barrier: needs all n at once
                std::lock_guard lock(m);
                ids[w] = std::this_thread::get_id();
                distinct.insert(ids[w]);
            },
            [&] { meanwhile_ran = true; });
        EXPECT_TRUE(meanwhile_ran);
        EXPECT_EQ(arrived.load(), n);
        EXPECT_EQ(distinct.size(), n);
        EXPECT_EQ(distinct.count(std::this_thread::get_id()), 0u);
        for (unsigned w = 0; w < std::min(n, 4u); ++w) {
            if (first[w] == std::thread::id{}) first[w] = ids[w];
            EXPECT_EQ(ids[w], first[w]) << "worker " << w << " moved to another thread";
        }
    }
}

}  // namespace
}  // namespace cellrt
