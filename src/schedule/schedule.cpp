#include "cellrt/schedule.hpp"

#include <algorithm>
#include <cstdint>
#include <exception>
#include <limits>
#include <thread>
#include <vector>

#include "cellrt/error.hpp"
#include "core/timer.hpp"
#include "cache_line.hpp"
#include "worker_team.hpp"

namespace cellrt {
namespace {

void store(Image& image, const PixelRect& r, std::span<const Vec3> colours) {
    for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x) image.at(x, y) = colours[static_cast<std::size_t>(y - r.y0) * r.width() + (x - r.x0)];
}

bool cancelled(const ScheduleOptions& o) { return o.cancel && o.cancel->load(std::memory_order_relaxed); }

// A worker's load, on a cache line of its own: each worker adds to it after every packet.
struct alignas(kCacheLine) PaddedLoad {
    WorkerLoad load;
};

// Calls `trace_packet` and adds the packet and the time it took to `load`.
template <class TracePacket>
void timed(WorkerLoad& load, TracePacket&& trace_packet) {
    const Timer timer;
    trace_packet();
    load.busy_seconds += timer.seconds();
    ++load.packets;
}

// The packets a worker has left, [begin, end), packed in one word so that the owner's claim (an add
// to begin) and a thief's cut (a compare-and-swap of end) are each one atomic step on it. The word is
// the range's whole state, so a compare-and-swap that finds the value it read is right to succeed,
// whatever happened to the range in between.
class alignas(kCacheLine) PacketRange {
public:
    // Owner only, while the range is empty (no thief modifies an empty range).
    void assign(std::uint32_t begin, std::uint32_t end) { bits_.store(pack(begin, end), std::memory_order_relaxed); }

    // Owner only: takes the first packet left (an empty range's begin passes its end by one).
    bool claim(std::size_t& packet) {
        const std::uint64_t old = bits_.fetch_add(1, std::memory_order_relaxed);
        packet = begin(old);
        return begin(old) < end(old);
    }

    std::uint32_t left() const {
        const std::uint64_t b = bits_.load(std::memory_order_relaxed);
        return begin(b) < end(b) ? end(b) - begin(b) : 0;
    }

    // A thief: cuts off the second half of what is left (the one packet, when one is left) and
    // returns it in [from, to); false when it found the range empty.
    bool steal(std::uint32_t& from, std::uint32_t& to) {
        std::uint64_t old = bits_.load(std::memory_order_relaxed);
        for (;;) {
            const std::uint32_t b = begin(old), e = end(old);
            if (b >= e) return false;
            const std::uint32_t mid = b + (e - b) / 2;
            if (bits_.compare_exchange_weak(old, pack(b, mid), std::memory_order_relaxed)) {
                from = mid;
                to = e;
                return true;
            }
        }
    }

private:
    static std::uint64_t pack(std::uint32_t b, std::uint32_t e) { return std::uint64_t{e} << 32 | b; }
    static std::uint32_t begin(std::uint64_t bits) { return static_cast<std::uint32_t>(bits); }
    static std::uint32_t end(std::uint64_t bits) { return static_cast<std::uint32_t>(bits >> 32); }

    std::atomic<std::uint64_t> bits_{0};
};

// Pull dispatch by work stealing (as Cilk's and TBB's schedulers; Blumofe & Leiserson 1999): worker w
// starts with the w-th of N contiguous runs of packets and claims them one by one from a word of its
// own (thieves only cut its end). Neighbouring packets, which read the same nodes and triangles and
// write neighbouring pixels, so go to the same core, and claims do not contend. With one shared
// counter, neighbours went to different cores: on the 2-core development machine SIMD packets took
// 7-8% longer with two workers than with one (medians of interleaved runs), against 2% now, and each
// claim moved the counter's cache line across (0.15 us a packet; docs/SCALING.md). A worker whose run
// is done takes the second half of the run with the most left, so the last packets are still handed
// out one at a time.
bool run_pull(const PacketGrid& grid, const ScheduleOptions& options, Image& image, const PacketTracer& trace,
              const Timer& frame, std::vector<PaddedLoad>& loads) {
    const auto workers = static_cast<unsigned>(loads.size());
    const std::size_t count = grid.count();
    // A run's bounds are 32-bit, and an emptied run's begin passes its end by one.
    if (count >= std::numeric_limits<std::uint32_t>::max())
        throw Error("a frame of " + std::to_string(count) + " packets is too many for pull dispatch: use larger packets");
    std::vector<PacketRange> ranges(workers);
    for (unsigned w = 0; w < workers; ++w)
        ranges[w].assign(static_cast<std::uint32_t>(count * w / workers), static_cast<std::uint32_t>(count * (w + 1) / workers));
    // Touched only for a progress callback (each worker counts its own packets in its load).
    alignas(kCacheLine) std::atomic<std::size_t> done{0};
    // Allocated here: a worker that allocates gets a malloc arena of its own, on every frame.
    std::vector<CacheLineVector<Vec3>> buffers(workers, CacheLineVector<Vec3>(static_cast<std::size_t>(grid.packet) * grid.packet));
    auto steal = [&](unsigned w) {
        for (;;) {
            unsigned victim = w;
            std::uint32_t most = 0;
            for (unsigned v = 0; v < workers; ++v)
                if (const std::uint32_t left = ranges[v].left(); v != w && left > most) {
                    most = left;
                    victim = v;
                }
            if (victim == w) return false;  // nothing left anywhere (stolen runs are traced by their thieves)
            std::uint32_t from, to;
            if (ranges[victim].steal(from, to)) {
                ranges[w].assign(from, to);
                return true;
            }
        }
    };
    // The next packet for worker w: its own, or one it stole (a thief may empty a run between the
    // steal that filled it and the claim, hence the loop); false when none is left anywhere.
    auto next = [&](unsigned w, std::size_t& p) {
        while (!ranges[w].claim(p))
            if (!steal(w)) return false;
        return true;
    };
    // A worker whose packet throws stops the others at their next packet; the team rethrows.
    std::atomic<bool> failed{false};
    auto work = [&](unsigned w) {
        WorkerLoad& load = loads[w].load;
        load.started_seconds = frame.seconds();
        CacheLineVector<Vec3>& colours = buffers[w];
        for (std::size_t p; !cancelled(options) && !failed.load(std::memory_order_relaxed) && next(w, p);) {
            const PixelRect r = grid.rect(p);
            const std::span<Vec3> out(colours.data(), static_cast<std::size_t>(r.pixels()));
            try {
                timed(load, [&] {
                    trace(w, r, out);
                    store(image, r, out);
                });
                if (options.progress) options.progress(done.fetch_add(1, std::memory_order_relaxed) + 1, count);
            } catch (...) {
                failed.store(true, std::memory_order_relaxed);
                throw;
            }
        }
        load.finished_seconds = frame.seconds();
    };
    detail::worker_team().run(workers, options.pin, options.idle_spin, work);
    std::size_t traced = 0;
    for (const PaddedLoad& l : loads) traced += l.load.packets;
    return traced == count;
}

// One worker's single-slot mailbox, after the Cell's SPU mailboxes: a slot the master writes a packet
// into and the worker its colours back, each side polling the other's flag. Polling (with a yield, so
// that an oversubscribed machine still makes progress) models the hardware channel, which costs
// hundreds of cycles, not an operating-system wake-up.
struct Mailbox {
    enum State : int { idle, work, done, failed, stop };  // failed: the packet threw, the worker is gone
    alignas(kCacheLine) std::atomic<int> state{idle};
    PixelRect rect{};
    CacheLineVector<Vec3> colours;
};

// Spins until `ready()` holds, yielding the processor between polls.
template <class Ready>
void poll(Ready&& ready) {
    while (!ready()) std::this_thread::yield();
}

bool run_mailbox(const PacketGrid& grid, const ScheduleOptions& options, Image& image, const PacketTracer& trace,
                 const Timer& frame, std::vector<PaddedLoad>& loads) {
    const auto workers = static_cast<unsigned>(loads.size());
    std::vector<Mailbox> boxes(workers);
    for (Mailbox& b : boxes) b.colours.resize(static_cast<std::size_t>(grid.packet) * grid.packet);

    auto work = [&](unsigned w) {
        Mailbox& box = boxes[w];
        WorkerLoad& load = loads[w].load;
        load.started_seconds = frame.seconds();
        for (;;) {
            int s;
            poll([&] { return (s = box.state.load(std::memory_order_acquire)) == Mailbox::work || s == Mailbox::stop; });
            if (s == Mailbox::stop) break;
            try {
                timed(load, [&] {
                    trace(w, box.rect,
                          std::span<Vec3>(box.colours.data(), static_cast<std::size_t>(box.rect.pixels())));
                });
            } catch (...) {
                box.state.store(Mailbox::failed, std::memory_order_release);
                throw;  // the team rethrows it once the master has stopped the others
            }
            box.state.store(Mailbox::done, std::memory_order_release);
        }
        load.finished_seconds = frame.seconds();
    };
    // The master (the study's PPU), on the calling thread: keeps the packet counter, posts each packet
    // to an idle worker, and writes every finished packet's colours into the frame buffer.
    // After a worker's packet threw, no packet is posted; the ones in flight are awaited. So after the
    // progress callback threw on the master: it left the workers polling for ever once (found by audit,
    // 2026-12-07), and a worker still tracing would have overwritten a stop with its `done`.
    std::size_t next = 0, done = 0, in_flight = 0;
    bool failed = false;
    std::exception_ptr progress_failure;
    auto master = [&] {
        for (;;) {
            const bool more = next < grid.count() && !cancelled(options) && !failed;
            if (in_flight == 0 && !more) break;
            bool progressed = false;
            for (Mailbox& b : boxes) {
                const int s = b.state.load(std::memory_order_acquire);
                if (s == Mailbox::failed) {
                    b.state.store(Mailbox::stop, std::memory_order_relaxed);  // never posted to again
                    --in_flight;
                    failed = progressed = true;
                }
                if (s == Mailbox::done) {
                    store(image, b.rect, std::span<const Vec3>(b.colours.data(), static_cast<std::size_t>(b.rect.pixels())));
                    b.state.store(Mailbox::idle, std::memory_order_relaxed);
                    --in_flight;
                    ++done;
                    progressed = true;
                    if (options.progress && !failed) {
                        try {
                            options.progress(done, grid.count());
                        } catch (...) {
                            progress_failure = std::current_exception();
                            failed = true;
                        }
                    }
                }
                if (b.state.load(std::memory_order_relaxed) == Mailbox::idle && next < grid.count() &&
                    !cancelled(options) && !failed) {
                    b.rect = grid.rect(next++);
                    b.state.store(Mailbox::work, std::memory_order_release);
                    ++in_flight;
                    progressed = true;
                }
            }
            if (!progressed) std::this_thread::yield();
        }
        for (Mailbox& b : boxes) b.state.store(Mailbox::stop, std::memory_order_release);
        if (progress_failure) std::rethrow_exception(progress_failure);
    };
    // Job 0 (the calling thread) is the master, job i + 1 worker i: the master has a core of its own
    // when there are cores to spare, as the PPU was a core of its own.
    detail::worker_team().run(workers + 1, options.pin, options.idle_spin, [&](unsigned j) {
        if (j == 0) master();
        else work(j - 1);
    });
    return done == grid.count();
}

}  // namespace

Dispatch parse_dispatch(const std::string& name) {
    if (name == "pull") return Dispatch::pull;
    if (name == "mailbox") return Dispatch::mailbox;
    throw Error("dispatch mode '" + name + "' is not one of: pull, mailbox");
}

const char* to_string(Dispatch d) { return d == Dispatch::pull ? "pull" : "mailbox"; }

PacketGrid::PacketGrid(int w, int h, int p) : width(w), height(h), packet(p) {
    if (w < 1 || h < 1) throw Error("image size must be positive");
    if (p < 1 || p > kMaxPacket)
        throw Error("packet edge " + std::to_string(p) + " must lie in [1, " + std::to_string(kMaxPacket) + "]");
}

PixelRect PacketGrid::rect(std::size_t index) const {
    if (index >= count())
        throw Error("PacketGrid::rect: packet " + std::to_string(index) + " of a grid of " + std::to_string(count()));
    const int cx = static_cast<int>(index % static_cast<std::size_t>(columns()));
    const int cy = static_cast<int>(index / static_cast<std::size_t>(columns()));
    const int x0 = cx * packet, y0 = cy * packet;
    return {x0, y0, x0 + std::min(packet, width - x0), y0 + std::min(packet, height - y0)};
}

void packet_order(const PixelRect& rect, std::span<std::uint32_t> order) {
    if (order.size() != static_cast<std::size_t>(rect.pixels())) throw Error("packet_order: the order must have one entry per pixel");
    // Interleaves the bits of x and y (x in the even bits): the Morton code of a pixel.
    auto spread = [](std::uint32_t v) {
        v &= 0xffff;
        v = (v | (v << 8)) & 0x00ff00ff;
        v = (v | (v << 4)) & 0x0f0f0f0f;
        v = (v | (v << 2)) & 0x33333333;
        return (v | (v << 1)) & 0x55555555;
    };
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    const auto w = static_cast<std::uint32_t>(rect.width());
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return (spread(a % w) | spread(a / w) << 1) < (spread(b % w) | spread(b / w) << 1);
    });
}

unsigned worker_count(const ScheduleOptions& options) {
    if (options.workers > kMaxWorkers)
        throw Error(std::to_string(options.workers) + " workers are more than the " + std::to_string(kMaxWorkers) +
                    " a frame may have");
    return options.workers ? options.workers : std::clamp(std::thread::hardware_concurrency(), 1u, kMaxWorkers);
}

bool run_packets(const PacketGrid& grid, const ScheduleOptions& options, Image& image, const PacketTracer& trace,
                 std::vector<WorkerLoad>* loads) {
    if (image.width != grid.width || image.height != grid.height ||
        image.pixels.size() != static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height))
        throw Error("frame buffer does not match the packet grid");
    std::vector<PaddedLoad> padded(worker_count(options));
    const Timer frame;
    const bool complete = options.dispatch == Dispatch::pull ? run_pull(grid, options, image, trace, frame, padded)
                                                             : run_mailbox(grid, options, image, trace, frame, padded);
    if (loads) {
        loads->clear();
        for (const PaddedLoad& p : padded) loads->push_back(p.load);
    }
    return complete;
}

}  // namespace cellrt
