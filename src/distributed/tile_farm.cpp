#include "distributed/tile_farm.hpp"

#include <sched.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>

#include "core/timer.hpp"
#include "distributed/faults.hpp"
#include "distributed/tile_window.hpp"

namespace cellrt::distributed {
namespace {

constexpr int kTagAssign = 1, kTagResult = 2;
constexpr std::int32_t kNoTile = -1;

// How often a rank's MPI thread polls while its tracer works: often enough to move a tile's fragments
// on as they are asked for, against a tile's milliseconds.
constexpr std::chrono::microseconds kWorkerPoll{100};
// Its wait while nothing is in flight and tiles are queued: long against a tile, short against a
// time-out, so that it still hears rank 0 end the job.
constexpr std::chrono::milliseconds kIdlePoll{5};

// A returned tile: its pixels (traced), the cause (failed), or nothing (skipped: the rank had failed
// before it reached the tile).
enum class Outcome : std::int32_t { traced, failed, skipped };

struct ResultHeader {
    std::int32_t tile;
    Outcome outcome;
    double seconds;  // the rank's time tracing the tile
};
static_assert(sizeof(ResultHeader) == 16);

// The longest cause a failed tile carries.
constexpr std::size_t kMaxCause = 4096;

// The frame in tiles of edge x edge pixels, row-major; tiles at the right and bottom are cut to it.
struct TileGrid {
    int width, height, edge, packet;

    int columns() const { return (width + edge - 1) / edge; }
    std::size_t count() const {
        return static_cast<std::size_t>(columns()) * static_cast<std::size_t>((height + edge - 1) / edge);
    }
    PixelRect rect(std::size_t t) const {
        const int x = static_cast<int>(t % static_cast<std::size_t>(columns())) * edge;
        const int y = static_cast<int>(t / static_cast<std::size_t>(columns())) * edge;
        return {x, y, std::min(x + edge, width), std::min(y + edge, height)};
    }
    std::size_t packets(std::size_t t) const {
        const PixelRect r = rect(t);
        return PacketGrid(r.width(), r.height(), packet).count();
    }
};

// Bytes a pixel takes on the way to rank 0.
std::size_t pixel_bytes(bool as_srgb8) { return as_srgb8 ? 3 : sizeof(Vec3); }

// The most pixels a tile of `grid` holds.
std::size_t max_tile_pixels(const TileGrid& grid) {
    std::size_t most = 0;
    for (std::size_t t = 0; t < grid.count(); ++t) most = std::max(most, static_cast<std::size_t>(grid.rect(t).pixels()));
    return most;
}

// How a traced tile's pixels reach rank 0: their form, and for the ranks that write them into the
// shared window, where. A writer's area holds `ahead` tiles, a slot each, used in turn: its n-th
// tile goes to slot n mod ahead. That slot last held its tile n - ahead, which rank 0 read before it
// sent the answer that handed the rank tile n (the answers arrive in order: one per tile returned,
// after `ahead` at the start), so no write overtakes a read.
struct TilePixels {
    bool srgb8;
    int ahead;
    std::size_t slot_bytes;
    const TileWindow& window;

    char* slot(char* area, std::uint64_t n) const {
        return area + slot_bytes * static_cast<std::size_t>(n % static_cast<std::uint64_t>(ahead));
    }
};

// A traced tile's pixels as they travel, written to `to`: its floats, or each channel's PNG byte.
void write_pixels(char* to, const Image& tile, bool as_srgb8) {
    if (!as_srgb8) {
        std::memcpy(to, tile.pixels.data(), tile.pixels.size() * sizeof(Vec3));
        return;
    }
    const Srgb8Image rgb = to_srgb8(tile);
    std::memcpy(to, rgb.rgb.data(), rgb.rgb.size());
}
// The same bytes, appended to a message.
void append_pixels(std::string& bytes, const Image& tile, bool as_srgb8) {
    const std::size_t at = bytes.size();
    bytes.resize(at + tile.pixels.size() * pixel_bytes(as_srgb8));
    write_pixels(bytes.data() + at, tile, as_srgb8);
}

// Puts a tile's travelled pixels (its rect's rows, packed) in their place in the frame.
void copy_into(Image& frame, const PixelRect& r, const char* pixels) {
    const std::size_t row = sizeof(Vec3) * static_cast<std::size_t>(r.width());
    for (int y = r.y0; y < r.y1; ++y)
        std::memcpy(&frame.at(r.x0, y), pixels + static_cast<std::size_t>(y - r.y0) * row, row);
}
void copy_into(Srgb8Image& frame, const PixelRect& r, const char* pixels) {
    const std::size_t row = 3 * static_cast<std::size_t>(r.width());
    for (int y = r.y0; y < r.y1; ++y)
        std::memcpy(&frame.rgb[3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(frame.width) + r.x0)],
                    pixels + static_cast<std::size_t>(y - r.y0) * row, row);
}
void copy_into(TileFrame& frame, const PixelRect& r, const char* pixels) {
    std::visit([&](auto& f) { copy_into(f, r, pixels); }, frame);
}
// Rank 0's own traced tile, in the frame's pixels.
void copy_into(TileFrame& frame, const PixelRect& r, const Image& tile) {
    if (Image* linear = std::get_if<Image>(&frame))
        return copy_into(*linear, r, reinterpret_cast<const char*>(tile.pixels.data()));
    copy_into(std::get<Srgb8Image>(frame), r, reinterpret_cast<const char*>(to_srgb8(tile).rgb.data()));
}

void add_tile(RankLoad& load, const RenderStats& s, std::size_t packets) {
    ++load.tiles;
    load.packets += packets;
    load.secondary_rays += s.secondary_rays;
    load.busy_seconds += s.seconds;
    if (load.workers.size() < s.workers.size()) load.workers.resize(s.workers.size());
    for (std::size_t w = 0; w < s.workers.size(); ++w) {
        load.workers[w].packets += s.workers[w].packets;
        load.workers[w].busy_seconds += s.workers[w].busy_seconds;
    }
}

// The test suite's way to make a rank die or stop answering once it holds a tile (faults.hpp):
// CELLRT_MPI_FAULT=kill:R or stall:R.
void inject_fault(int rank) {
    if (fault_named("kill", rank)) std::raise(SIGKILL);
    if (fault_named("stall", rank))
        for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
}

// Sends kept until MPI is done with their bytes.
class Outbox {
public:
    void send(std::string bytes, int dest, int tag) {
        sends_.push_back({std::move(bytes), MPI_REQUEST_NULL});
        Send& s = sends_.back();
        MPI_Isend(s.bytes.data(), static_cast<int>(s.bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD, &s.request);
        progress();
    }
    // Lets MPI move the sends on and forgets those it is done with.
    void progress() {
        for (int done = 1; done && !sends_.empty(); sends_.pop_front()) {
            MPI_Test(&sends_.front().request, &done, MPI_STATUS_IGNORE);
            if (!done) break;
        }
    }
    bool empty() const { return sends_.empty(); }
    void flush(const Session& session, const std::string& what) {
        for (; !sends_.empty(); sends_.pop_front()) session.wait(sends_.front().request, what);
    }

private:
    struct Send {
        std::string bytes;
        MPI_Request request;
    };
    std::deque<Send> sends_;
};

double cpu_seconds(clockid_t clock) {
    timespec t{};
    clock_gettime(clock, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::string int_bytes(std::int32_t v) { return std::string(reinterpret_cast<const char*>(&v), sizeof v); }

RenderOptions tile_options(const RenderOptions& options) {
    RenderOptions o = options;
    o.threads = rank_threads(options.threads);
    o.progress = nullptr;  // a tile's packets are not the frame's: rank 0 reports the frame's
    return o;
}

// The frame's renderer for this rank's tiles, or null with `failure` saying why.
std::unique_ptr<FrameRenderer> start_renderer(const Scene& scene, const Accelerator& accel, const RenderOptions& o,
                                              std::optional<std::string>& failure) {
    try {
        return std::make_unique<FrameRenderer>(scene, accel, o);
    } catch (const std::exception& e) {
        failure = e.what();
        return nullptr;
    }
}

// A rank other than 0: traces the tiles rank 0 hands it and returns each one's pixels (in its area of
// the shared window, with a header that says so, or in the message); one more answer is owed for
// every tile returned and `ahead` at the start, until rank 0 answers that none is left. A thread of
// its own traces while this one, the only one that calls MPI, polls: a tile's pixels sent as a message
// exceed the eager limit of MPI's shared-memory and network transports, so they travel in fragments
// that move only while the sender calls MPI. A rank that called MPI only between tiles sent each
// tile's last fragments a tile or more late and waited for its next tile (with Open MPI and no
// single-copy transport, 16 ranks on one machine: busy 40 % of the frame; docs/DISTRIBUTED.md).
RankLoad trace_for_master(const Session& session, const Scene& scene, const Accelerator& accel,
                          const RenderOptions& options, const TileGrid& grid, int ahead, const TilePixels& pixels,
                          std::optional<std::string>& failure) {
    const RenderOptions o = tile_options(options);
    RankLoad load;
    load.threads = o.threads;
    Timer frame_timer;
    const double cpu_start = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);

    // Between the threads: tiles to trace, traced tiles' messages, and the word that no tile is left.
    std::mutex mutex;
    std::condition_variable assigned, returned;
    std::deque<std::int32_t> queue;
    std::deque<std::string> traced;
    bool no_more = false;
    std::thread tracer([&] {
        Image tile;
        const std::unique_ptr<FrameRenderer> renderer = start_renderer(scene, accel, o, failure);
        std::uint64_t sequence = 0;  // tiles taken from the queue
        for (bool first = true;; first = false) {
            std::int32_t t = kNoTile;
            {
                std::unique_lock lock(mutex);
                assigned.wait(lock, [&] { return !queue.empty() || no_more; });
                if (queue.empty()) return;
                t = queue.front();
                queue.pop_front();
                if (queue.empty()) returned.notify_one();  // time to look for the next tiles
            }
            const std::uint64_t n = sequence++;
            if (first) inject_fault(session.rank());
            std::string bytes(sizeof(ResultHeader), '\0');
            ResultHeader header{t, Outcome::skipped, 0.0};
            if (!failure) {
                try {
                    RenderStats s;
                    renderer->render_window(grid.rect(static_cast<std::size_t>(t)), tile, &s);
                    add_tile(load, s, grid.packets(static_cast<std::size_t>(t)));
                    header.outcome = Outcome::traced;
                    header.seconds = s.seconds;
                    if (pixels.window.writes()) write_pixels(pixels.slot(pixels.window.mine(), n), tile, pixels.srgb8);
                    else append_pixels(bytes, tile, pixels.srgb8);
                } catch (const std::exception& e) {
                    failure = e.what();
                    header.outcome = Outcome::failed;
                    bytes.resize(sizeof(ResultHeader));  // no pixels half written before the cause
                    bytes.append(failure->substr(0, kMaxCause));
                }
            }
            std::memcpy(bytes.data(), &header, sizeof header);
            const std::lock_guard lock(mutex);
            traced.push_back(std::move(bytes));
            returned.notify_one();
        }
    });

    int pending = ahead;     // answers rank 0 still owes this rank
    std::size_t held = 0;    // tiles received and not yet returned
    std::int32_t incoming = kNoTile;
    MPI_Request answer = MPI_REQUEST_NULL;
    bool posted = false;
    Outbox outbox;
    Timer waiting;  // since this rank last had a tile in hand
    for (;;) {
        std::deque<std::string> ready;
        {
            const std::lock_guard lock(mutex);
            ready.swap(traced);
        }
        if (!ready.empty()) pixels.window.sync();  // the tracer's pixels before their headers
        for (std::string& bytes : ready) {
            outbox.send(std::move(bytes), 0, kTagResult);
            ++pending;
            --held;
        }
        outbox.progress();
        while (pending > 0) {
            if (!posted) MPI_Irecv(&incoming, 1, MPI_INT32_T, 0, kTagAssign, MPI_COMM_WORLD, &answer);
            posted = true;
            int done = 0;
            MPI_Test(&answer, &done, MPI_STATUS_IGNORE);
            if (!done) break;
            posted = false;
            --pending;
            if (incoming == kNoTile) continue;
            ++held;
            const std::lock_guard lock(mutex);
            queue.push_back(incoming);
            assigned.notify_one();
        }
        if (pending == 0 && held == 0) break;
        if (held > 0) waiting = Timer();
        session.poll_ending(waiting.seconds(), "rank 0's next tile");
        // Quick polls while pixels travel or the tracer has nothing queued; else little to do here
        // until a tile is traced or the queue empties (answers wait in MPI's queue meanwhile).
        std::unique_lock lock(mutex);
        if (outbox.empty() && !queue.empty())
            returned.wait_for(lock, kIdlePoll, [&] { return !traced.empty() || queue.empty(); });
        else
            returned.wait_for(lock, kWorkerPoll, [&] { return !traced.empty(); });
    }
    {
        const std::lock_guard lock(mutex);
        no_more = true;
    }
    assigned.notify_one();
    tracer.join();
    outbox.flush(session, "rank 0's receipt of the last tiles");
    load.seconds = frame_timer.seconds();
    load.cpu_seconds = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu_start;
    return load;
}

// Rank 0: hands out tiles and gathers them into `frame`, which it makes (floats, or the PNG's bytes
// with pixels.srgb8), while a thread of its own traces tiles too.
RankLoad master(const Session& session, const Scene& scene, const Accelerator& accel, const RenderOptions& options,
                const TileGrid& grid, int ahead, const TilePixels& pixels, TileFrame& frame,
                std::optional<std::string>& failure) {
    const auto ranks = static_cast<std::size_t>(session.size());
    const std::size_t count = grid.count();
    std::size_t all_packets = 0;
    for (std::size_t t = 0; t < count; ++t) all_packets += grid.packets(t);
    Timer frame_timer;
    const double cpu_start = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
    const double master_start = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    std::atomic<std::size_t> next{0}, gathered{0};
    std::atomic<bool> stop{false}, local_done{false};
    auto claim = [&]() -> std::int32_t {
        if (stop) return kNoTile;
        const std::size_t t = next.fetch_add(1);
        return t < count ? static_cast<std::int32_t>(t) : kNoTile;
    };

    // The other ranks' tiles: `ahead` each at the start, then one per tile returned.
    Outbox outbox;
    std::vector<std::size_t> outstanding(ranks, 0);
    std::vector<double> heard(ranks, 0.0), tile_time(ranks, 0.0);  // last result; a tile's mean time
    std::vector<std::uint64_t> results(ranks, 0);  // results received, by rank
    // The master polls often enough to answer a rank before its queued tiles run out, and no more
    // often: a poll costs some 25 us of rank 0's cores (docs/DISTRIBUTED.md). The ranks' own tracing
    // times set it, not the gaps between their results, which grow when a rank waits. A tile's pixels
    // take several polls on each side where they travel in fragments (a transport without single
    // copies moves a few fragments a poll): 8 polls in the time of the tiles a rank has queued
    // (with 4, such a transport left 2 ranks waiting as before; with 16, rank 0's polls cost 3 %
    // more with a single-copy transport; docs/DISTRIBUTED.md).
    auto poll_interval = [&] {
        double fastest = 0.0;
        for (std::size_t r = 1; r < ranks; ++r)
            if (tile_time[r] > 0.0 && (fastest == 0.0 || tile_time[r] < fastest)) fastest = tile_time[r];
        if (fastest == 0.0) return kPollInterval;
        const double seconds = std::clamp(fastest * (ahead - 1) / 8.0, 100e-6, 2e-3);
        return std::chrono::microseconds(static_cast<long long>(seconds * 1e6));
    };
    // A rank that writes into the window sends only a header, or a failed tile's cause.
    std::vector<int> buffer_bytes(ranks, 0);
    for (std::size_t r = 1; r < ranks; ++r)
        buffer_bytes[r] = static_cast<int>(
            sizeof(ResultHeader) + std::max(pixels.window.written_by(static_cast<int>(r)) ? 0 : pixels.slot_bytes, kMaxCause));
    std::vector<std::string> buffers(ranks);
    std::vector<MPI_Request> requests(ranks, MPI_REQUEST_NULL);
    auto answer = [&](std::size_t r) {
        const std::int32_t t = claim();
        outbox.send(int_bytes(t), static_cast<int>(r), kTagAssign);
        if (t != kNoTile) ++outstanding[r];
    };
    for (std::size_t r = 1; r < ranks; ++r) {
        buffers[r].resize(static_cast<std::size_t>(buffer_bytes[r]));
        for (int a = 0; a < ahead; ++a) answer(r);
        if (outstanding[r] > 0)
            MPI_Irecv(buffers[r].data(), buffer_bytes[r], MPI_BYTE, static_cast<int>(r), kTagResult,
                      MPI_COMM_WORLD, &requests[r]);
    }

    // The frame, made once the other ranks have their first tiles. Its memory is not written when
    // made (cellrt/zeroed_array.hpp): its pages are faulted in by the copies of the tiles, where
    // zeroing 25 MB of 1080p floats took some 5 ms of rank 0's core first.
    if (pixels.srgb8) frame = Srgb8Image(grid.width, grid.height);
    else frame = Image(grid.width, grid.height);

    // Rank 0's own tiles, claimed from the same counter; the thread never calls MPI.
    const RenderOptions o = tile_options(options);
    RankLoad load;
    load.threads = o.threads;
    std::thread local([&] {
        Image tile;
        const std::unique_ptr<FrameRenderer> renderer = start_renderer(scene, accel, o, failure);
        if (!renderer) stop = true;
        for (std::int32_t t = claim(); t != kNoTile; t = claim()) {
            try {
                RenderStats s;
                const PixelRect r = grid.rect(static_cast<std::size_t>(t));
                renderer->render_window(r, tile, &s);
                copy_into(frame, r, tile);
                add_tile(load, s, grid.packets(static_cast<std::size_t>(t)));
                gathered += grid.packets(static_cast<std::size_t>(t));
            } catch (const std::exception& e) {
                failure = e.what();
                stop = true;
            }
        }
        load.seconds = frame_timer.seconds();
        local_done = true;
    });

    std::vector<int> indices(ranks);
    const double timeout = static_cast<double>(session.timeout().count()) / 1e3;
    std::size_t reported = 0;
    for (;;) {
        const bool remote = std::any_of(outstanding.begin(), outstanding.end(), [](std::size_t n) { return n > 0; });
        if (!remote && local_done) break;
        int completed = 0;
        if (remote)
            MPI_Testsome(static_cast<int>(ranks), requests.data(), &completed, indices.data(), MPI_STATUSES_IGNORE);
        if (completed == MPI_UNDEFINED) completed = 0;
        if (completed > 0) pixels.window.sync();  // the pixels of the headers received, before reading
        for (int i = 0; i < completed; ++i) {
            const auto r = static_cast<std::size_t>(indices[static_cast<std::size_t>(i)]);
            ResultHeader header;
            std::memcpy(&header, buffers[r].data(), sizeof header);
            --outstanding[r];
            const std::uint64_t n = results[r]++;
            heard[r] = frame_timer.seconds();
            if (header.outcome == Outcome::traced)
                tile_time[r] = tile_time[r] > 0.0 ? 0.75 * tile_time[r] + 0.25 * header.seconds : header.seconds;
            if (header.outcome == Outcome::traced) {
                const auto t = static_cast<std::size_t>(header.tile);
                const bool shared = pixels.window.written_by(static_cast<int>(r));
                copy_into(frame, grid.rect(t),
                          shared ? pixels.slot(pixels.window.of(static_cast<int>(r)), n) : buffers[r].data() + sizeof header);
                if (shared) pixels.window.sync();  // the slot read before the answer frees it
                gathered += grid.packets(t);
            } else if (header.outcome == Outcome::failed) {
                stop = true;  // the rank reports its cause itself when the ranks agree
            }
            answer(r);
            if (outstanding[r] > 0)
                MPI_Irecv(buffers[r].data(), buffer_bytes[r], MPI_BYTE, static_cast<int>(r), kTagResult,
                          MPI_COMM_WORLD, &requests[r]);
        }
        const double now = frame_timer.seconds();
        for (std::size_t r = 1; r < ranks; ++r)
            if (outstanding[r] > 0 && now - heard[r] > timeout)
                session.abort("rank " + std::to_string(r) + " has returned no tile for " + session.timeout_text() +
                              ", " + std::to_string(outstanding[r]) +
                              " of its tiles outstanding (it stopped answering, or its tiles take longer than --rank-timeout)");
        if (options.progress && gathered != reported) options.progress(reported = gathered, all_packets);
        if (completed == 0) std::this_thread::sleep_for(poll_interval());
    }
    local.join();
    outbox.flush(session, "the last tiles' answers");
    load.cpu_seconds = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu_start;
    load.master_cpu_seconds = cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - master_start;
    return load;
}

std::string load_bytes(const RankLoad& load) {
    std::string out;
    auto put = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
    put(load.threads);
    put(load.tiles);
    put(load.packets);
    put(load.secondary_rays);
    put(load.busy_seconds);
    put(load.seconds);
    put(load.cpu_seconds);
    put(load.master_cpu_seconds);
    put(load.window_writers);
    for (const WorkerLoad& w : load.workers) {
        put(w.packets);
        put(w.busy_seconds);
    }
    return out;
}

RankLoad parse_load(const std::string& bytes) {
    RankLoad load;
    std::size_t at = 0;
    auto get = [&](auto& v) {
        std::memcpy(&v, bytes.data() + at, sizeof v);
        at += sizeof v;
    };
    get(load.threads);
    get(load.tiles);
    get(load.packets);
    get(load.secondary_rays);
    get(load.busy_seconds);
    get(load.seconds);
    get(load.cpu_seconds);
    get(load.master_cpu_seconds);
    get(load.window_writers);
    while (at + sizeof(std::size_t) + sizeof(double) <= bytes.size()) {
        WorkerLoad w;
        get(w.packets);
        get(w.busy_seconds);
        load.workers.push_back(w);
    }
    return load;
}

}  // namespace

unsigned rank_threads(unsigned threads) {
    if (threads) return threads;
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return 0;
    return std::clamp(static_cast<unsigned>(CPU_COUNT(&allowed)), 1u, kMaxWorkers);
}

void render_tiles(const Session& session, const Scene& scene, const Accelerator& accel, const RenderOptions& options,
                  const TileOptions& tiles, TileFrame& frame, RenderStats* stats, std::vector<RankLoad>* loads) {
    if (tiles.tile < 1 || tiles.tile > kMaxImageSide)
        throw Error("tile edge " + std::to_string(tiles.tile) + " must lie in [1, " + std::to_string(kMaxImageSide) +
                    "]");
    if (tiles.ahead < 1 || tiles.ahead > kMaxAhead)
        throw Error("tiles ahead " + std::to_string(tiles.ahead) + " must lie in [1, " + std::to_string(kMaxAhead) +
                    "]");
    check_image_size(options.width, options.height);
    static_cast<void>(PacketGrid(options.width, options.height, options.packet));  // refuses a bad packet edge
    const TileGrid grid{options.width, options.height, tiles.tile, options.packet};
    std::optional<std::string> failure;
    Timer timer;
    RankLoad mine;
    const std::size_t slot_bytes = max_tile_pixels(grid) * pixel_bytes(tiles.srgb8);
    TileWindow window(session, tiles.gather == TileGather::window, slot_bytes * static_cast<std::size_t>(tiles.ahead),
                      static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height) *
                          pixel_bytes(tiles.srgb8));
    const TilePixels pixels{tiles.srgb8, tiles.ahead, slot_bytes, window};
    if (session.leader()) {
        mine = master(session, scene, accel, options, grid, tiles.ahead, pixels, frame, failure);
        mine.window_writers = window.writers();
    } else {
        mine = trace_for_master(session, scene, accel, options, grid, tiles.ahead, pixels, failure);
    }
    window.close();
    const double seconds = timer.seconds();
    session.agree(failure, "the frame");
    const std::vector<std::string> all = session.gather(load_bytes(mine), "the ranks' figures");
    if (!session.leader()) return;
    std::vector<RankLoad> gathered;
    for (const std::string& b : all) gathered.push_back(parse_load(b));
    if (stats) {
        *stats = RenderStats{};
        stats->seconds = seconds;
        stats->primary_rays = static_cast<std::uint64_t>(options.width) * options.height;
        for (const RankLoad& l : gathered) {
            stats->secondary_rays += l.secondary_rays;
            // Every rank's threads, in rank order, a rank's `threads` entries each: a rank without a
            // tile had none listed, so the list could not be matched to the ranks (found by audit,
            // 2026-12-07).
            for (std::size_t w = 0; w < std::max<std::size_t>(l.threads, l.workers.size()); ++w)
                stats->workers.push_back(w < l.workers.size()
                                             ? WorkerLoad{l.workers[w].packets, l.workers[w].busy_seconds, 0.0, l.seconds}
                                             : WorkerLoad{0, 0.0, 0.0, l.seconds});
        }
    }
    if (loads) *loads = std::move(gathered);
}

}  // namespace cellrt::distributed
