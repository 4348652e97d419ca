// Work distribution for a frame: the image cut into packets of P x P pixels, and the two ways of
// handing packets to worker threads that the scaling study compares.
//
// - mailbox: the study's section 4.1. One master thread owns the packet counter; it hands each packet
//   to an idle worker through that worker's single-slot mailbox, waits for the worker's colours and
//   writes them into the frame buffer. Every packet passes through the master twice, which is why the
//   study saw no scaling past two workers with 2 x 2 packets.
// - pull: each worker starts on a contiguous run of packets, claims them one by one and writes the
//   frame buffer itself; a worker whose run is done takes half of the longest run left (work
//   stealing). Nothing passes through a master, and claims do not contend.
// Both give the same image: a pixel's colour depends only on its own rays.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "cellrt/image.hpp"

namespace cellrt {

enum class Dispatch { pull, mailbox };

inline constexpr std::chrono::microseconds kDefaultIdleSpin{1000};

Dispatch parse_dispatch(const std::string& name);  // "pull" | "mailbox"; throws cellrt::Error
const char* to_string(Dispatch d);

struct PixelRect {
    int x0, y0, x1, y1;  // half-open
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    int pixels() const { return width() * height(); }
};

// The largest packet edge PacketGrid accepts.
inline constexpr int kMaxPacket = 256;

// The image in packets of `packet` x `packet` pixels (1 <= packet <= kMaxPacket), row-major; packets
// at the right and bottom edges are cut to the image (partial packets are traced, never dropped).
// Throws cellrt::Error for a side below 1 or a packet edge out of range.
struct PacketGrid {
    int width, height, packet;

    PacketGrid(int w, int h, int p);
    // Rounded up without width + packet - 1, which overflows for a side near INT_MAX (sides are >= 1).
    int columns() const { return (width - 1) / packet + 1; }
    int rows() const { return (height - 1) / packet + 1; }
    std::size_t count() const { return static_cast<std::size_t>(columns()) * rows(); }
    PixelRect rect(std::size_t index) const;  // throws cellrt::Error unless index < count()
};

// The pixels of a packet in the order its rays are traced: Morton (Z) order, so that any 4, 8 or 16
// consecutive rays (one SIMD packet) cover a compact 2 x 2, 4 x 2 or 4 x 4 block. `order` (of
// rect.pixels() entries; throws cellrt::Error otherwise) receives offsets y * rect.width() + x within
// the rect.
void packet_order(const PixelRect& rect, std::span<std::uint32_t> order);

struct ScheduleOptions {
    Dispatch dispatch = Dispatch::pull;
    unsigned workers = 0;  // 0: all hardware threads; at most kMaxWorkers
    // Pin worker i to core i (under mailbox dispatch the master to core 0 and worker i to core i + 1;
    // Linux; ignored where unavailable), counting the cores the calling thread may use (under taskset
    // or a cpuset, the i-th of those). Worker 0 (pull) or the master (mailbox) is the calling thread.
    bool pin = false;
    // After the frame the workers poll for the next one this long before they sleep, so that frames
    // drawn back to back do not pay a wake-up per worker (0: sleep at once; docs/SCALING.md).
    std::chrono::microseconds idle_spin{kDefaultIdleSpin};
    const std::atomic<bool>* cancel = nullptr;
    // (packets done, packets in all). An exception it throws ends the frame as a packet's does. Called
    // from the worker threads, several at once, under pull dispatch (from the master under mailbox):
    // it must be thread-safe, and counts may arrive out of order (keep the largest).
    std::function<void(std::size_t, std::size_t)> progress;
};

// Computes the colours of one packet (row-major over rect, rect.pixels() entries) on worker `worker`.
using PacketTracer = std::function<void(unsigned worker, const PixelRect& rect, std::span<Vec3> colours)>;

// What one worker did in a frame: the packets it traced and the time it spent tracing them (its
// PacketTracer calls and, under pull dispatch, writing their colours), and when it started and
// finished, counted from the start of the frame. A frame of N workers that takes T seconds leaves
// N * T - sum(busy) to the schedule itself: waking the workers (sum(started)), claiming packets
// between them, and waiting for the last one (sum(T - finished)).
struct WorkerLoad {
    std::size_t packets = 0;
    double busy_seconds = 0.0;
    double started_seconds = 0.0;   // when the worker woke and began to claim packets
    double finished_seconds = 0.0;  // when it found no packet left (or the frame cancelled)
};

// The most workers a frame may have: more than any machine cellrt runs on has cores, few enough that
// their threads and per-worker buffers are allocated without a second thought.
inline constexpr unsigned kMaxWorkers = 1024;

// Number of worker threads `options` asks for; throws cellrt::Error for more than kMaxWorkers.
unsigned worker_count(const ScheduleOptions& options);

// Traces every packet of `grid` into `image` (which must be grid.width x grid.height); when `loads`
// is given, it receives one WorkerLoad per worker. Returns false when cancelled before all packets
// were traced. `trace` runs on every worker at once (on packets of its own); frames run one at a
// time on the process's one team of worker threads, so a second caller waits for the first, and a
// frame started from inside one (`trace` or a progress callback calling run_packets or render) is
// refused with cellrt::Error, where it waited for ever. The first exception `trace` throws on any worker stops the others at
// their next packet and is rethrown here once all have stopped.
bool run_packets(const PacketGrid& grid, const ScheduleOptions& options, Image& image, const PacketTracer& trace,
                 std::vector<WorkerLoad>* loads = nullptr);

}  // namespace cellrt
