// The packet scheduler: every dispatch mode, worker count and packet size gives the same image.
#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <limits>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "core/timer.hpp"
#include "error_of.hpp"
#include "scenes.hpp"
#include "schedule/worker_team.hpp"

namespace cellrt {
namespace {

using namespace std::chrono_literals;

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

// Each worker's load names the packets that worker traced, its busy time covers the time they took
// (each packet here takes at least 200 microseconds), and its start and finish enclose them.
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
        const Timer frame;
        ASSERT_TRUE(run_packets(
            grid, o, image,
            [&](unsigned w, const PixelRect&, std::span<Vec3>) {
                ++traced[w];
                const Timer t;
                while (t.seconds() < 200e-6) {}
            },
            &loads));
        const double frame_seconds = frame.seconds();
        ASSERT_EQ(loads.size(), kWorkers) << to_string(d);
        std::size_t packets = 0;
        for (unsigned w = 0; w < kWorkers; ++w) {
            EXPECT_EQ(loads[w].packets, traced[w].load()) << to_string(d) << " worker " << w;
            EXPECT_GE(loads[w].busy_seconds, 200e-6 * static_cast<double>(loads[w].packets)) << to_string(d);
            // Its packets lie between its start and its finish, which lie inside the frame.
            EXPECT_GE(loads[w].started_seconds, 0.0) << to_string(d);
            EXPECT_LE(loads[w].started_seconds + loads[w].busy_seconds, loads[w].finished_seconds) << to_string(d);
            EXPECT_LE(loads[w].finished_seconds, frame_seconds) << to_string(d);
            packets += loads[w].packets;
        }
        EXPECT_EQ(packets, grid.count()) << to_string(d);
    }
}

// Pull dispatch starts worker w on the w-th run of packets; here the first worker's run is slow (each
// packet 5 ms, the rest free), so the others must take its packets from it, one at a time at the end,
// and every packet is still traced exactly once.
TEST(Schedule, PullWorkersTakePacketsFromTheBusiest) {
    const PacketGrid grid(48, 40, 4);  // 120 packets: worker 0 starts with packets 0..29 of 4 workers
    Image image(48, 40);
    constexpr unsigned kWorkers = 4;
    std::vector<std::atomic<int>> traced(grid.count());
    std::vector<std::atomic<unsigned>> by(grid.count());
    ScheduleOptions o;
    o.workers = kWorkers;
    ASSERT_TRUE(run_packets(grid, o, image, [&](unsigned w, const PixelRect& r, std::span<Vec3>) {
        const std::size_t p = static_cast<std::size_t>(r.y0 / 4) * grid.columns() + static_cast<std::size_t>(r.x0 / 4);
        ++traced[p];
        by[p] = w;
        if (p < grid.count() / kWorkers) {
            const Timer t;
            while (t.seconds() < 5e-3) {}
        }
    }));
    std::set<unsigned> slow_run_workers;
    for (std::size_t p = 0; p < grid.count(); ++p) {
        EXPECT_EQ(traced[p].load(), 1) << "packet " << p;
        if (p < grid.count() / kWorkers) slow_run_workers.insert(by[p].load());
    }
    EXPECT_GE(slow_run_workers.size(), 2u) << "nobody took packets from the busy worker";
}

// Many workers on few cores, packets of one pixel, frame after frame: no packet lost or traced twice
// while workers race to take the last packets from each other.
TEST(Schedule, PullTracesEveryPacketOnceWhileWorkersRace) {
    const PacketGrid grid(31, 23, 1);
    Image image(31, 23);
    std::vector<std::atomic<int>> traced(grid.count());
    for (unsigned workers : {2u, 5u, 8u, 13u}) {
        for (int frame = 0; frame < 20; ++frame) {
            for (auto& t : traced) t = 0;
            ScheduleOptions o;
            o.workers = workers;
            ASSERT_TRUE(run_packets(grid, o, image, [&](unsigned, const PixelRect& r, std::span<Vec3>) {
                ++traced[static_cast<std::size_t>(r.y0) * 31 + static_cast<std::size_t>(r.x0)];
            }));
            for (std::size_t p = 0; p < grid.count(); ++p) ASSERT_EQ(traced[p].load(), 1) << workers << " workers, packet " << p;
        }
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

// In the library's words: the program puts its option's name in front.
TEST(Schedule, RejectsBadSettings) {
    using test::error_of;
    EXPECT_EQ(error_of([] { PacketGrid(16, 16, 0); }), "packet edge 0 must lie in [1, 256]");
    EXPECT_EQ(error_of([] { PacketGrid(16, 16, kMaxPacket + 1); }), "packet edge 257 must lie in [1, 256]");
    EXPECT_EQ(error_of([] { parse_dispatch("push"); }), "dispatch mode 'push' is not one of: pull, mailbox");
    EXPECT_EQ(parse_dispatch("mailbox"), Dispatch::mailbox);
    std::vector<std::uint32_t> order(15);
    EXPECT_THROW(packet_order(PixelRect{0, 0, 4, 4}, order), Error);
    // A packet past the grid's last would be a rect below the image.
    EXPECT_EQ(PacketGrid(10, 10, 4).rect(8).y1, 10);
    EXPECT_EQ(error_of([] { PacketGrid(10, 10, 4).rect(9); }), "PacketGrid::rect: packet 9 of a grid of 9");
    // A worker count is refused before a thread or buffer is made for it.
    ScheduleOptions many;
    many.workers = kMaxWorkers + 1;
    EXPECT_EQ(error_of([&] { worker_count(many); }), "1025 workers are more than the 1024 a frame may have");
    Image image(16, 16);
    const PacketTracer nothing = [](unsigned, const PixelRect&, std::span<Vec3>) {};
    EXPECT_EQ(error_of([&] { run_packets(PacketGrid(16, 16, 4), many, image, nothing); }),
              "1025 workers are more than the 1024 a frame may have");
    // A frame buffer of the grid's sides but not its pixels (a moved-from Image keeps its sides) was
    // written past its end (found by audit, 2026-12-07).
    Image hollow;
    hollow.width = hollow.height = 16;
    EXPECT_EQ(error_of([&] { run_packets(PacketGrid(16, 16, 4), ScheduleOptions{}, hollow, nothing); }),
              "frame buffer does not match the packet grid");
}

// The highest core of `set` (-1: none), and a set of that one core: the affinity tests' one core apart.
int last_core(const cpu_set_t& set) {
    int last = -1;
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &set)) last = c;
    return last;
}
cpu_set_t just(int core) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(core, &set);
    return set;
}

// Pinned workers stay on the cores the caller may use: under `taskset -c 1` they were pinned to core 0
// and core 1 of the machine, or left unpinned where a cpuset refused (found by audit, 2026-12-07).
TEST(Schedule, PinnedWorkersStayOnTheCallersCores) {
    cpu_set_t before;
    ASSERT_EQ(pthread_getaffinity_np(pthread_self(), sizeof before, &before), 0);
    const int last = last_core(before);
    if (last <= 0) GTEST_SKIP() << "one core only: nothing to tell apart";
    const cpu_set_t only = just(last);
    ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof only, &only), 0);
    std::mutex m;
    std::set<int> cpus;
    Image image(32, 32);
    for (const Dispatch d : {Dispatch::pull, Dispatch::mailbox}) {
        ScheduleOptions o;
        o.dispatch = d;
        o.workers = 3;
        o.pin = true;
        run_packets(PacketGrid(32, 32, 4), o, image, [&](unsigned, const PixelRect&, std::span<Vec3>) {
            std::lock_guard lock(m);
            cpus.insert(sched_getcpu());
        });
    }
    pthread_setaffinity_np(pthread_self(), sizeof before, &before);
    EXPECT_EQ(cpus, std::set<int>{last});
}

// Sides near INT_MAX: the packet count was rounded up through width + packet - 1, which overflowed
// (columns() -8388607 for a side of INT_MAX; found by audit, 2026-12-07).
TEST(Schedule, GridsOfTheLargestSidesCountTheirPackets) {
    constexpr int kMax = std::numeric_limits<int>::max();
    const PacketGrid grid(kMax, 1, kMaxPacket);
    EXPECT_EQ(grid.columns(), kMax / kMaxPacket + 1);
    EXPECT_EQ(grid.count(), static_cast<std::size_t>(kMax / kMaxPacket + 1));
    const PixelRect last = grid.rect(grid.count() - 1);
    EXPECT_EQ(last.x1, kMax);
    EXPECT_EQ(last.x0, kMax / kMaxPacket * kMaxPacket);
    EXPECT_EQ(PacketGrid(1, kMax, 7).rows(), (kMax - 1) / 7 + 1);
}

// A packet that throws on any worker ends the frame under either dispatch mode: run_packets rethrows
// its exception once the other workers have stopped (never std::terminate on a worker thread, never
// a master waiting for a worker that is gone), and the next frame runs as usual.
TEST(Schedule, APacketThatThrowsEndsTheFrameWithItsException) {
    const PacketGrid grid(64, 64, 4);
    for (const Dispatch d : {Dispatch::pull, Dispatch::mailbox})
        for (const unsigned workers : {1u, 2u, 4u})
            for (const std::size_t failing : {std::size_t(0), std::size_t(136), grid.count() - 1}) {
                ScheduleOptions o;
                o.dispatch = d;
                o.workers = workers;
                Image image(64, 64);
                const PixelRect bad = grid.rect(failing);
                try {
                    run_packets(grid, o, image, [&](unsigned, const PixelRect& r, std::span<Vec3> c) {
                        if (r.x0 == bad.x0 && r.y0 == bad.y0) throw Error("packet " + std::to_string(failing));
                        std::fill(c.begin(), c.end(), Vec3(1.f));
                    });
                    ADD_FAILURE() << to_string(d) << ", " << workers << " workers: no exception";
                } catch (const Error& e) {
                    EXPECT_EQ(std::string(e.what()), "packet " + std::to_string(failing));
                }
                EXPECT_TRUE(run_packets(grid, o, image, [](unsigned, const PixelRect&, std::span<Vec3> c) {
                    std::fill(c.begin(), c.end(), Vec3(2.f));
                }));
                EXPECT_TRUE(std::all_of(image.pixels.begin(), image.pixels.end(),
                                        [](const Vec3& v) { return v == Vec3(2.f); }));
            }
}

// So does a progress callback that throws: under mailbox dispatch its master used to leave the
// workers polling for ever.
TEST(Schedule, AProgressCallbackThatThrowsEndsTheFrameWithItsException) {
    const PacketGrid grid(64, 64, 4);
    for (const Dispatch d : {Dispatch::pull, Dispatch::mailbox})
        for (const unsigned workers : {1u, 2u, 4u}) {
            ScheduleOptions o;
            o.dispatch = d;
            o.workers = workers;
            o.progress = [](std::size_t done, std::size_t) {
                if (done == 2) throw Error("stop");
            };
            Image image(64, 64);
            const PacketTracer fill = [](unsigned, const PixelRect&, std::span<Vec3> c) { std::fill(c.begin(), c.end(), Vec3(1.f)); };
            EXPECT_EQ(test::error_of([&] { run_packets(grid, o, image, fill); }), "stop") << to_string(d) << ", " << workers;
            o.progress = nullptr;
            EXPECT_TRUE(run_packets(grid, o, image, fill)) << to_string(d) << ", " << workers;
        }
}

// A frame started from a packet's trace (found by audit, 2026-12-07: it waited for ever) is refused,
// under both dispatch modes and on one worker too, and the team goes on.
TEST(Schedule, AFrameStartedFromATraceIsRefused) {
    const PacketGrid grid(32, 32, 8);
    for (const Dispatch d : {Dispatch::pull, Dispatch::mailbox})
        for (const unsigned workers : {1u, 2u}) {
            ScheduleOptions o;
            o.dispatch = d;
            o.workers = workers;
            Image image(32, 32), inner(32, 32);
            const PacketTracer fill = [](unsigned, const PixelRect&, std::span<Vec3> c) { std::fill(c.begin(), c.end(), Vec3(1.f)); };
            const PacketTracer nested = [&](unsigned, const PixelRect&, std::span<Vec3>) { run_packets(grid, o, inner, fill); };
            EXPECT_EQ(test::error_of([&] { run_packets(grid, o, image, nested); }),
                      "a frame was started from inside a frame (a progress callback or a packet's trace): frames run one "
                      "at a time on the process's one team of workers")
                << to_string(d) << ", " << workers;
            EXPECT_TRUE(run_packets(grid, o, image, fill)) << to_string(d) << ", " << workers;
        }
}

// The team behind both dispatch modes: every job index runs once per run, all at the same time (a
// job that waits for all the others would hang otherwise), job 0 on the calling thread and job j on
// the same thread from run to run, and a larger run after a smaller one grows the team; whether the
// threads were still polling after the last run, asleep, or left out of the runs in between.
TEST(WorkerTeam, RunsEveryJobAtOnceOnKeptThreads) {
    detail::WorkerTeam team;
    std::vector<std::thread::id> first(6);
    using Run = std::pair<unsigned, std::chrono::microseconds>;
    for (const auto& [n, spin] : {Run{4u, 0us}, Run{2u, 1000us}, Run{4u, 1000us}, Run{6u, 0us}, Run{1u, 0us}, Run{3u, 0us},
                                  Run{6u, 1000us}, Run{1u, 1000us}, Run{1u, 0us}, Run{6u, 0us}}) {
        std::atomic<unsigned> arrived{0};
        std::mutex m;
        std::vector<std::thread::id> ids(n);
        std::set<std::thread::id> distinct;
        team.run(n, false, spin, [&](unsigned j) {
            arrived.fetch_add(1);
            while (arrived.load() < n) std::this_thread::yield();  // a barrier: needs all n at once
            std::lock_guard lock(m);
            ids[j] = std::this_thread::get_id();
            distinct.insert(ids[j]);
        });
        EXPECT_EQ(arrived.load(), n);
        EXPECT_EQ(distinct.size(), n);
        EXPECT_EQ(ids[0], std::this_thread::get_id());
        for (unsigned j = 1; j < n; ++j) {
            if (first[j] == std::thread::id{}) first[j] = ids[j];
            EXPECT_EQ(ids[j], first[j]) << "job " << j << " moved to another thread";
        }
    }
}

// Free (unpinned) jobs run anywhere their caller may run, whoever started the team: its threads
// inherited the cores of the thread that started them, and a team started from a thread confined to
// one core kept every later caller's helpers there (found by audit, 2026-12-07).
TEST(WorkerTeam, FreeJobsRunWhereTheirCallerMay) {
    cpu_set_t all;
    ASSERT_EQ(pthread_getaffinity_np(pthread_self(), sizeof all, &all), 0);
    const int last = last_core(all);
    if (last <= 0) GTEST_SKIP() << "one core only: nothing to tell apart";
    const cpu_set_t only = just(last);
    detail::WorkerTeam team;
    // The helper's cores during a run of two jobs from a thread allowed `caller`.
    auto helpers_cores = [&](const cpu_set_t& caller) {
        cpu_set_t seen;
        CPU_ZERO(&seen);
        std::thread([&] {
            pthread_setaffinity_np(pthread_self(), sizeof caller, &caller);
            team.run(2, false, 0us, [&](unsigned j) {
                if (j == 1) pthread_getaffinity_np(pthread_self(), sizeof seen, &seen);
            });
        }).join();
        return seen;
    };
    const cpu_set_t first = helpers_cores(only), second = helpers_cores(all), third = helpers_cores(only);
    EXPECT_TRUE(CPU_EQUAL(&first, &only));
    EXPECT_TRUE(CPU_EQUAL(&second, &all)) << CPU_COUNT(&second) << " of " << CPU_COUNT(&all) << " cores";
    EXPECT_TRUE(CPU_EQUAL(&third, &only));
}

// An exception from a job on a team thread reaches the caller once the other jobs are done (the first
// thrown when several throw), and the team still runs.
TEST(WorkerTeam, RethrowsAnExceptionFromAnyThread) {
    detail::WorkerTeam team;
    for (const unsigned failing : {1u, 3u}) {
        std::atomic<unsigned> others{0};
        try {
            team.run(4, false, 0us, [&](unsigned j) {
                if (j == failing) throw Error("job " + std::to_string(j) + " failed");
                ++others;
            });
            ADD_FAILURE() << "job " << failing << ": no exception";
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()), "job " + std::to_string(failing) + " failed");
        }
        EXPECT_EQ(others.load(), 3u);
    }
    EXPECT_THROW(team.run(4, false, 0us, [](unsigned j) { throw Error("job " + std::to_string(j)); }), Error);
    std::atomic<unsigned> ran{0};
    team.run(4, false, 0us, [&](unsigned) { ++ran; });
    EXPECT_EQ(ran.load(), 4u);
}

// An exception from job 0 reaches the caller once the other jobs are done, and the team still runs.
TEST(WorkerTeam, RethrowsJobZerosExceptionAfterTheOthers) {
    detail::WorkerTeam team;
    std::atomic<unsigned> others{0};
    EXPECT_THROW(team.run(3, false, 0us,
                          [&](unsigned j) {
                              if (j == 0) throw Error("job 0 failed");
                              const Timer t;
                              while (t.seconds() < 1e-3) {}
                              ++others;
                          }),
                 Error);
    EXPECT_EQ(others.load(), 2u);
    team.run(3, false, 0us, [&](unsigned) { ++others; });
    EXPECT_EQ(others.load(), 5u);
}

}  // namespace
}  // namespace cellrt
