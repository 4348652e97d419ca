// The plain programs' cluster: this one process (cluster.hpp).
#include "cluster.hpp"

#include <algorithm>
#include <cstdio>
#include <thread>
#include <numeric>

namespace cellrt::cli::cluster {
namespace {
const char* g_program = "cellrt";
}  // namespace

void start(int&, char**&, const char* program) { g_program = program; }
int finish(int status) { return status; }
int rank() { return 0; }
int ranks() { return 1; }
unsigned cores() { return std::max(1u, std::thread::hardware_concurrency()); }
void print_error(const std::exception& e) { std::fprintf(stderr, "%s: error: %s\n", g_program, e.what()); }
const char* program() { return g_program; }
bool distributed() { return false; }
void add_render_options(CLI::App&) {}
void add_sweep_options(CLI::App&) {}
void add_bench_options(CLI::App&) {}
void together(const std::function<void()>& step, const std::string&) { step(); }
Scene load_scene(const std::string& spec) { return cellrt::load_scene(spec); }

void render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, bool, Frame& frame,
            RenderStats& stats, nlohmann::json&) {
    cellrt::render(scene, accel, options, frame.emplace<Image>(), &stats);
}

std::vector<std::size_t> share(std::size_t count) {
    std::vector<std::size_t> all(count);
    std::iota(all.begin(), all.end(), std::size_t{0});
    return all;
}

std::vector<std::string> gather(const std::string& mine) { return {mine}; }
std::string broadcast(const std::string& leaders) { return leaders; }

// This process ran every run, in order.
std::vector<std::string> gather_runs(std::size_t, const std::vector<std::size_t>&, std::vector<std::string> results) {
    return results;
}

void sweep(std::size_t count, const std::function<std::string(std::size_t)>& run,
           const std::function<void(std::size_t, const std::string&)>& take, const std::string&) {
    for (std::size_t i = 0; i < count; ++i) take(i, run(i));
}

}  // namespace cellrt::cli::cluster
