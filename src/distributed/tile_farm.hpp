// Image-parallel rendering over the ranks of an MPI job: the study's PPE and SPEs (Hapala, section
// 4.1) across machines. Rank 0 is the master: it cuts the frame into tiles of T x T pixels, hands
// each rank `ahead` tiles at the start and one more for every tile a rank returns, so a rank always
// has the next tile at hand while its last result travels (asking ahead); it gathers the tiles into
// the frame. Every rank, rank 0 included (on a thread of its own beside the master), traces a tile
// on all its cores through the process's scheduler (FrameRenderer::render_window). Ranks on rank 0's
// machine hand their pixels over through shared memory (tile_window.hpp). A pixel's colour
// depends only on its own rays, so the frame is the one-process frame, bit for bit, for every number
// of ranks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <variant>
#include <vector>

#include "cellrt/image.hpp"
#include "cellrt/render.hpp"
#include "distributed/session.hpp"

namespace cellrt::distributed {

// How the ranks' pixels reach rank 0. window: the ranks on rank 0's machine write them into memory it
// shares with them (distributed/tile_window.hpp) and send only each tile's header; ranks on other
// machines send them. messages: every rank sends them.
enum class TileGather { window, messages };

struct TileOptions {
    int tile = 128;  // tile edge in pixels (the frame's edge tiles are cut to it)
    int ahead = 3;   // tiles a rank holds: the one it traces and those queued behind it
    // Tiles travel as 8-bit sRGB pixels, 3 bytes where floats take 12: for a frame written as PNG,
    // whose bytes each rank makes from its own pixels as the PNG writer would (cellrt/image.hpp).
    bool srgb8 = false;
    TileGather gather = TileGather::window;
};

// The frame rank 0 gathers: linear floats, or with TileOptions::srgb8 the PNG's 8-bit pixels.
using TileFrame = std::variant<Image, Srgb8Image>;

inline constexpr int kMaxAhead = 64;

// What one rank did in a frame.
struct RankLoad {
    unsigned threads = 0;
    std::uint64_t tiles = 0, packets = 0, secondary_rays = 0;
    double busy_seconds = 0.0;     // tracing its tiles (FrameRenderer::render_window)
    double seconds = 0.0;          // from the frame's start on this rank until it had no tile left
    double cpu_seconds = 0.0;      // the process's CPU time in that span, every thread's
    double master_cpu_seconds = 0.0;  // rank 0: its master thread's share of it
    int window_writers = 0;           // rank 0: the ranks that wrote their pixels into the shared window
    std::vector<WorkerLoad> workers;  // its threads' packets and time tracing, summed over its tiles
};

// Renders the frame of `options` (width x height) on every rank: each calls it with the same scene,
// structure and options. On rank 0, `frame` receives the image (the alternative that tiles.srgb8
// names), `stats` the frame's figures (rays of
// all ranks; seconds: rank 0's wall time for the frame) and `loads` one RankLoad per rank; on the
// others they are left alone. options.progress is called on rank 0 with the frame's packets gathered.
// A rank that fails (a tracer's exception, a cancelled render) stops the frame: every rank throws
// AgreedError naming it. A rank that stops answering ends the job after the session's time-out.
void render_tiles(const Session& session, const Scene& scene, const Accelerator& accel, const RenderOptions& options,
                  const TileOptions& tiles, TileFrame& frame, RenderStats* stats, std::vector<RankLoad>* loads);

// The worker threads a rank runs for options.threads == 0: the cores it may run on (mpirun binds a
// rank to its share of a machine's cores), not all of the machine's.
unsigned rank_threads(unsigned threads);

}  // namespace cellrt::distributed
