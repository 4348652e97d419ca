// cellrt-mpi's cluster: the ranks of an MPI job (cluster.hpp, docs/DISTRIBUTED.md). Every rank runs
// the same command; rank 0 prints and writes, the others trace and stay silent unless they alone
// fail.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>

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
};
Options g_options;

distributed::Session& session() { return *g_session; }

void add_common_options(CLI::App& cmd) {
    cmd.add_flag("--broadcast-scene", g_options.broadcast_scene,
                 "Rank 0 loads the scene and sends its triangles to the other ranks (default: every rank loads it "
                 "from its path)");
    cmd.add_option_function<double>(
           "--rank-timeout",
           [](double s) { session().set_timeout(std::chrono::milliseconds(static_cast<long long>(s * 1e3))); },
           "Seconds a rank waits for another before it ends the job with a message (default " +
               std::to_string(distributed::kDefaultRankTimeout.count()) + ")")
        ->check(CLI::Range(0.1, 86400.0));
}

}  // namespace

void start(int& argc, char**& argv) { g_session = std::make_unique<distributed::Session>(argc, argv); }

int finish(int status) {
    const int agreed = session().finish(status);
    g_session.reset();
    return agreed;
}

int rank() { return session().rank(); }
int ranks() { return session().size(); }
unsigned cores() { return distributed::rank_threads(0); }

void print_error(const std::exception& e) {
    if (dynamic_cast<const distributed::AgreedError*>(&e)) {
        if (leader()) std::fprintf(stderr, "cellrt: error: %s\n", e.what());
    } else {
        std::fprintf(stderr, "cellrt: error: rank %d: %s\n", rank(), e.what());
    }
}

void add_render_options(CLI::App& cmd) {
    add_common_options(cmd);
    cmd.add_option("--tile", g_options.tiles.tile, "Tile edge in pixels: rank 0 hands out tiles of T x T pixels")
        ->capture_default_str()
        ->check(CLI::Range(1, kMaxImageSide));
    cmd.add_option("--ahead", g_options.tiles.ahead,
                   "Tiles each rank holds: the one it traces and those queued behind it")
        ->capture_default_str()
        ->check(CLI::Range(1, distributed::kMaxAhead));
}

void add_sweep_options(CLI::App& cmd) { add_common_options(cmd); }

void together(const std::function<void()>& step, const std::string& name) { session().together(step, name); }

Scene load_scene(const std::string& spec) {
    return distributed::load_scene_on_every_rank(session(), spec, g_options.broadcast_scene);
}

void render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, Image& frame,
            RenderStats& stats, nlohmann::json& report) {
    std::vector<distributed::RankLoad> loads;
    distributed::render_tiles(session(), scene, accel, options, g_options.tiles, frame, &stats, &loads);
    if (!leader()) return;
    report["tile"] = g_options.tiles.tile;
    report["ahead"] = g_options.tiles.ahead;
    report["scene_from"] = g_options.broadcast_scene ? "broadcast" : "path";
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

}  // namespace cellrt::cli::cluster
