// The processes one command runs on, as the subcommands see them: the plain cellrt program is one
// process (cluster_local.cpp); cellrt-mpi is the ranks of an MPI job (mpi/cluster_mpi.cpp,
// docs/DISTRIBUTED.md). The commands are compiled once and call these the same way in both programs;
// the program links one implementation, so the plain program holds no MPI code at all.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"

namespace cellrt::cli::cluster {

// Before and after everything else: start() joins the job (MPI_Init); finish() returns the exit
// status agreed by all processes (the largest) and leaves the job.
void start(int& argc, char**& argv);
int finish(int status);

int rank();   // 0 in the plain program
int ranks();  // 1 in the plain program
unsigned cores();  // the cores this process may run on (a rank's share of its machine under MPI)
inline bool leader() { return rank() == 0; }  // prints, and writes the outputs

// Prints the error a command ended with, as "cellrt: error: ..." (under MPI once, by rank 0, for an
// error all ranks agreed on, and with the rank's number otherwise).
void print_error(const std::exception& e);

// The options a distributed command adds (none in the plain program).
void add_render_options(CLI::App& cmd);
void add_sweep_options(CLI::App& cmd);

// Runs `step` on every process; when it throws on any, it throws on all, naming the first process at
// fault and its cause (in the plain program: `step` itself).
void together(const std::function<void()>& step, const std::string& name);

// The scene `spec` on every process (cellrt::load_scene in the plain program).
Scene load_scene(const std::string& spec);

// Renders the frame with every process (cellrt::render in the plain program). On the leader `frame`
// and `stats` receive the frame and its figures and `report` what each process did (left alone in
// the plain program, whose figures are its workers'); elsewhere they are left alone.
void render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, Image& frame,
            RenderStats& stats, nlohmann::json& report);

// The independent runs 0..count-1 this process traces: every `ranks()`-th from rank().
std::vector<std::size_t> share(std::size_t count);

// Every process's `mine`, in rank order, on the leader (empty elsewhere).
std::vector<std::string> gather(const std::string& mine);

}  // namespace cellrt::cli::cluster
