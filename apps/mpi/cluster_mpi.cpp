// cellrt-mpi's cluster: the ranks of an MPI job (cluster.hpp, docs/DISTRIBUTED.md). Every rank runs
// the same command; rank 0 prints and writes, the others trace and stay silent unless they alone
// fail.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "cellrt/error.hpp"
#include "cellrt/workload.hpp"
#include "cluster.hpp"
#include "distributed/scene_transfer.hpp"
#include "distributed/session.hpp"
#include "distributed/tile_farm.hpp"

namespace cellrt::cli::cluster {
namespace {

std::unique_ptr<distributed::Session> g_session;

struct Options {
    bool broadcast_scene = false;
    distributed::TileOptions tiles;
    std::string gather = "window";
};
Options g_options;

distributed::Session& session() { return *g_session; }

// The longest time-out, a day, and the default of the sweeps (cache-study, the benchmarks): a rank
// waits for the others' runs at the end of its share as long as the longest share lasts (a full sweep
// of the shared scenes runs for hours on one machine), where a frame's ranks wait for one tile.
constexpr std::chrono::seconds kLongestRankTimeout{86400};

void add_timeout_option(CLI::App& cmd, std::chrono::seconds fallback) {
    // The command's own default, set when its options are read (before --rank-timeout's value): set
    // here, when the commands are registered, the last one's (cache-study's day) was every command's
    // (found by audit, 2026-12-07: render's 120 s was a day). A bare command line is render's, the
    // session's own default.
    cmd.preparse_callback([fallback](std::size_t) { session().set_timeout(fallback); });
    cmd.add_option_function<double>(
           "--rank-timeout",
           // A NaN or an infinity never gets here: strict_numbers (cluster.hpp) refuses them first.
           [](double s) { session().set_timeout(std::chrono::milliseconds(static_cast<long long>(s * 1e3))); },
           "Seconds a rank waits for another before it ends the job with a message: the longest a tile or a "
           "step on one rank (a build, a load) may take beyond the others' (default " +
               std::to_string(fallback.count()) + ")")
        ->check(CLI::Range(0.1, static_cast<double>(kLongestRankTimeout.count())));
}

void add_common_options(CLI::App& cmd, std::chrono::seconds timeout) {
    cmd.add_flag("--broadcast-scene", g_options.broadcast_scene,
                 "Rank 0 loads the scene and sends its triangles to the other ranks (default: every rank loads it "
                 "from its path)");
    add_timeout_option(cmd, timeout);
}

}  // namespace

void start(int& argc, char**& argv, const char* program) {
    g_session = std::make_unique<distributed::Session>(argc, argv, program);
}

int finish(int status) {
    const int agreed = session().finish(status);
    g_session.reset();
    return agreed;
}

int rank() { return session().rank(); }
int ranks() { return session().size(); }
unsigned cores() { return distributed::rank_threads(0); }

const char* program() { return session().program().c_str(); }
bool distributed() { return true; }

void print_error(const std::exception& e) {
    if (dynamic_cast<const distributed::AgreedError*>(&e)) {
        if (leader()) std::fprintf(stderr, "%s: error: %s\n", session().program().c_str(), e.what());
    } else {
        std::fprintf(stderr, "%s: error: rank %d: %s\n", session().program().c_str(), rank(), e.what());
    }
}

void add_render_options(CLI::App& cmd) {
    add_common_options(cmd, distributed::kDefaultRankTimeout);
    cmd.add_option("--tile", g_options.tiles.tile, "Tile edge in pixels: rank 0 hands out tiles of T x T pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, kMaxImageSide));
    cmd.add_option("--ahead", g_options.tiles.ahead,
                   "Tiles each rank holds: the one it traces and those queued behind it")
        ->capture_default_str()
        ->check(CLI::Range(1, distributed::kMaxAhead));
    cmd.add_option("--gather", g_options.gather,
                   "How the ranks' pixels reach rank 0: window (ranks on rank 0's machine write them into memory "
                   "it shares with them, the others send them) or messages (every rank sends them)")
        ->capture_default_str()
        ->check(CLI::IsMember({"window", "messages"}));
}

void add_sweep_options(CLI::App& cmd) { add_common_options(cmd, kLongestRankTimeout); }
void add_bench_options(CLI::App& cmd) { add_timeout_option(cmd, kLongestRankTimeout); }

void together(const std::function<void()>& step, const std::string& name) { session().together(step, name); }

Scene load_scene(const std::string& spec) {
    // Every rank on one side of the broadcast: a rank loading the file while rank 0 sends it would
    // wait for its part of the broadcast until the time-out.
    agree(g_options.broadcast_scene ? "with" : "without", "comparing --broadcast-scene",
          [](const std::string& mine, const std::string& leaders) {
              return "it was started " + mine + " --broadcast-scene, rank 0 " + leaders + " it";
          });
    return distributed::load_scene_on_every_rank(session(), spec, g_options.broadcast_scene);
}

void render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, bool png, Frame& frame,
            RenderStats& stats, nlohmann::json& report) {
    std::vector<distributed::RankLoad> loads;
    distributed::TileOptions tiles = g_options.tiles;
    tiles.srgb8 = png;
    tiles.gather = g_options.gather == "messages" ? distributed::TileGather::messages : distributed::TileGather::window;
    // Every rank traces the frame rank 0 gathers: what decides its pixels (the size, the shading,
    // Embree or an exact structure) and the tiles' exchange. The scene's fingerprint covers the view
    // file's size only: a rank started with another --size (mpirun's `A : B`) made a wrong frame
    // without a word (found by review, 2026-12-07). The structure, threads and dispatch may differ.
    const std::string mine = std::to_string(options.width) + "x" + std::to_string(options.height) + ", " +
                             to_string(options.shading.shading) + " shading" +
                             (options.shading.shading == Shading::ao
                                  ? " with " + std::to_string(options.shading.ao_samples) + " AO rays"
                                  : std::string()) +
                             (accel.stats().name == "embree" ? ", Embree" : "") + ", tiles of " +
                             std::to_string(tiles.tile) + " ahead " + std::to_string(tiles.ahead) + ", " +
                             (png ? "PNG" : "float") + " pixels by " + g_options.gather;
    agree(mine, "comparing the frames", [](const std::string& mine, const std::string& leaders) {
        return "its frame (" + mine + ") differs from rank 0's (" + leaders + ")";
    });
    distributed::render_tiles(session(), scene, accel, options, tiles, frame, &stats, &loads);
    if (!leader()) return;
    report["tile"] = tiles.tile;
    report["ahead"] = tiles.ahead;
    report["pixels"] = tiles.srgb8 ? "srgb8" : "float";
    report["gather"] = g_options.gather;
    report["window_ranks"] = loads.empty() ? 0 : loads[0].window_writers;
    report["scene_from"] = g_options.broadcast_scene ? "broadcast" : "path";
    report["rank_timeout_seconds"] = static_cast<double>(session().timeout().count()) / 1e3;
    report["ranks"] = nlohmann::json::array();
    for (std::size_t r = 0; r < loads.size(); ++r) {
        const distributed::RankLoad& l = loads[r];
        report["ranks"].push_back({{"rank", r},
                                   {"threads", l.threads},
                                   {"tiles", l.tiles},
                                   {"packets", l.packets},
                                   {"secondary_rays", l.secondary_rays},
                                   {"busy_seconds", l.busy_seconds},
                                   {"seconds", l.seconds},
                                   {"cpu_seconds", l.cpu_seconds}});
        if (r == 0) report["ranks"].back()["master_cpu_seconds"] = l.master_cpu_seconds;
    }
}

std::vector<std::size_t> share(std::size_t count) {
    std::vector<std::size_t> mine;
    for (auto i = static_cast<std::size_t>(rank()); i < count; i += static_cast<std::size_t>(ranks()))
        mine.push_back(i);
    return mine;
}

std::vector<std::string> gather(const std::string& mine) { return session().gather(mine, "the runs' results"); }

std::string broadcast(const std::string& leaders) {
    std::uint64_t length = leaders.size();
    session().broadcast(&length, sizeof length, "rank 0's word");
    std::string bytes = leaders;
    bytes.resize(length);
    session().broadcast(bytes.data(), bytes.size(), "rank 0's word");
    return bytes;
}

// Each result travels as its run's index, its length and its bytes.
std::vector<std::string> gather_runs(std::size_t count, const std::vector<std::size_t>& mine,
                                     std::vector<std::string> results) {
    std::string bytes;
    for (std::size_t k = 0; k < mine.size(); ++k) {
        const std::uint64_t head[2] = {mine[k], results[k].size()};
        bytes.append(reinterpret_cast<const char*>(head), sizeof head);
        bytes += results[k];
    }
    std::vector<std::string> all(leader() ? count : 0);
    for (const std::string& b : gather(bytes))
        for (std::size_t at = 0; at < b.size();) {
            std::uint64_t head[2];
            std::memcpy(head, b.data() + at, sizeof head);
            at += sizeof head;
            all.at(head[0]) = b.substr(at, head[1]);
            at += head[1];
        }
    return all;
}

void sweep(std::size_t count, const std::function<std::string(std::size_t)>& run,
           const std::function<void(std::size_t, const std::string&)>& take, const std::string& name) {
    const std::vector<std::size_t> mine = share(count);
    std::vector<std::string> results;
    together([&] { for (std::size_t i : mine) results.push_back(run(i)); }, name);
    const std::vector<std::string> all = gather_runs(count, mine, std::move(results));
    for (std::size_t i = 0; i < all.size(); ++i) take(i, all[i]);
}

}  // namespace cellrt::cli::cluster
