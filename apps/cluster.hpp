// The processes one command runs on, as the subcommands see them: the plain programs (cellrt,
// cellrt_bench, cellrt_scaling) are one process (cluster_local.cpp); their -mpi variants are the ranks
// of an MPI job (mpi/cluster_mpi.cpp, docs/DISTRIBUTED.md). The commands are compiled once and call
// these the same way in both programs; the program links one implementation, so the plain program
// holds no MPI code at all.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <string_view>
#include <system_error>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <algorithm>
#include <vector>

#include "cellrt/error.hpp"
#include "cellrt/image.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"

namespace cellrt::cli::cluster {

// Before and after everything else: start() joins the job (MPI_Init) and names the program in its
// messages ("PROGRAM: error: ..."); finish() returns the exit status agreed by all processes (the
// largest) and leaves the job.
void start(int& argc, char**& argv, const char* program);
int finish(int status);

int rank();   // 0 in the plain program
int ranks();  // 1 in the plain program
unsigned cores();  // the cores this process may run on (a rank's share of its machine under MPI)
inline bool leader() { return rank() == 0; }  // prints, and writes the outputs

// Prints the error a command ended with, as "PROGRAM: error: ..." (under MPI once, by rank 0, for an
// error all ranks agreed on, and with the rank's number otherwise).
void print_error(const std::exception& e);
// The program's name, as start() was given it.
const char* program();
// Whether this is the MPI program (cellrt-mpi), at any rank count: its frames are cut into tiles.
bool distributed();

// Runs `step` on every process; when it throws on any, it throws on all, naming the first process at
// fault and its cause (in the plain program: `step` itself).
void together(const std::function<void()>& step, const std::string& name);

// Refuses a list option that names one value twice (`--structures kd kd`, `--packets 8 8`): its runs
// would be made and written twice.
template <class T>
void check_no_repeats(const std::string& option, const std::vector<T>& values) {
    for (std::size_t i = 0; i < values.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (values[i] == values[j]) {
                std::ostringstream named;
                named << values[i];
                throw Error(option + " names '" + named.str() + "' twice");
            }
}

// The exit status once what the program printed has reached standard output: a report printed into
// a full disk or a closed pipe (`cellrt info scene.json > /dev/full`) is lost, and a status of 0
// would say it was not. Call it with the status the command ended with, before finish().
inline int flushed(int status) {
    if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return status;
    if (leader()) std::fprintf(stderr, "%s: error: standard output: write failed\n", program());
    // The error the run ends with, whatever it had to say (`info --device cuda > /dev/full` kept the
    // no-device status 3, its line lost; found by audit, 2026-12-07), but an interrupt's 130.
    return status == 130 ? status : 1;
}

// Integer options read as decimal digits only (no sign, no leading zero), and numbers as
// std::from_chars reads them, finite: CLI11 (2.1) reads integers by strtoll's rules, so that
// `--threads 010` meant 8, `0x10` 16, " 4" 4 and "" 0, where the values in files and -P are decimal.
// Added to every option of `app` and its subcommands whose type is INT, UINT or FLOAT (call it after
// the options are made).
inline void strict_numbers(CLI::App& app) {
    const auto kind = [](const CLI::Option* o) {
        const std::string t = o->get_type_name();
        return t.substr(0, t.find(':'));
    };
    const CLI::Validator integer(
        [](std::string& value) -> std::string {
            // No leading zero either, which CLI11's conversion would read as octal.
            const bool digits = !value.empty() && value.find_first_not_of("0123456789") == std::string::npos &&
                                (value == "0" || value[0] != '0');
            return digits ? std::string() : "'" + value + "' is not a whole number in decimal digits";
        },
        "", "decimal");
    const CLI::Validator number(
        [](std::string& value) -> std::string {
            const std::string_view v = !value.empty() && value[0] == '+' ? std::string_view(value).substr(1) : value;
            double d = 0;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), d);
            // Finite too: a NaN passes CLI11's range checks, whose comparisons are false.
            const bool whole = !v.empty() && end == v.data() + v.size() && ec == std::errc() && std::isfinite(d);
            return whole ? std::string() : "'" + value + "' is not a finite decimal number";
        },
        "", "decimal number");
    // Put ahead of the option's own checks (transform inserts first; these change nothing), so that
    // `--repeats ""` is named as not a number rather than as "Value  not in range 1 to 1000".
    for (CLI::Option* o : app.get_options()) {
        const std::string k = kind(o);
        if (k == "INT" || k == "UINT") o->transform(integer);
        else if (k == "FLOAT") o->transform(number);
    }
    for (CLI::App* sub : app.get_subcommands({})) strict_numbers(*sub);
}

// The options a distributed command adds (none in the plain program): a frame's, a sweep's (the
// cache study's: its ranks each load every scene) and a benchmark's (whose sweeps run for hours, so
// that a rank's wait for the others' runs has a longer time-out).
void add_render_options(CLI::App& cmd);
void add_sweep_options(CLI::App& cmd);
void add_bench_options(CLI::App& cmd);

// The scene `spec` on every process (cellrt::load_scene in the plain program).
Scene load_scene(const std::string& spec);

// A rendered frame: linear floats, or the 8-bit sRGB pixels of its PNG.
using Frame = std::variant<Image, Srgb8Image>;

// Renders the frame with every process (cellrt::render in the plain program). On the leader `frame`
// and `stats` receive the frame and its figures and `report` what each process did (left alone in
// the plain program, whose figures are its workers'); elsewhere they are left alone. With `png` (the
// frame is written as PNG) cellrt-mpi's ranks send their pixels as the PNG's bytes, a quarter of the
// floats, and `frame` holds those; the plain program renders floats either way.
void render(const Scene& scene, const Accelerator& accel, const RenderOptions& options, bool png, Frame& frame,
            RenderStats& stats, nlohmann::json& report);

// The independent runs 0..count-1 this process traces: every `ranks()`-th from rank().
std::vector<std::size_t> share(std::size_t count);

// Every process's `mine`, in rank order, on the leader (empty elsewhere).
std::vector<std::string> gather(const std::string& mine);

// The leader's `leaders` on every process.
std::string broadcast(const std::string& leaders);

// Compares this process's `mine` with the leader's. Where they differ, the step `name` fails on every
// process (`together`) with `differs(mine, leaders)` as its message: settings that must be one for the
// whole job (mpirun's `A : B` form can start ranks with different lines) are checked before any
// collective that depends on them, which would otherwise wait for its time-out or pair unlike calls.
inline void agree(const std::string& mine, const std::string& name,
                  const std::function<std::string(const std::string& mine, const std::string& leaders)>& differs) {
    const std::string leaders = broadcast(mine);
    together([&] { if (mine != leaders) throw Error(differs(mine, leaders)); }, name);
}

// The arguments parse() read, after the program's name.
inline std::vector<std::string>& arguments_read() {
    static std::vector<std::string> arguments;
    return arguments;
}

// A sweep's ranks each run their share of one set of runs, which the leader writes as one result: a
// rank started with another line (mpirun's `A : B` form) ran other runs, and the leader wrote
// uninitialised rows for those it expected (found by audit, 2026-12-07). The line is compared but
// for the options `local` and their values (where a machine keeps its copy of the scenes, say). The
// frame of `render` is compared by what decides its pixels instead, as its ranks may differ in
// structure and threads.
inline void same_command_line(const std::string& what, const std::vector<std::string>& local = {}) {
    std::string line;
    const std::vector<std::string>& args = arguments_read();
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string name = args[i].substr(0, args[i].find('='));
        if (std::find(local.begin(), local.end(), name) != local.end()) {
            if (name == args[i]) ++i;  // its value, the next argument
            continue;
        }
        line += (line.empty() ? "'" : " '") + args[i] + "'";
    }
    agree(line, "comparing the command lines", [&](const std::string& mine, const std::string& leaders) {
        return "its command line (" + mine + ") differs from rank 0's (" + leaders + "): " + what +
               " runs one command line on every rank";
    });
}

// Parses the command line into `app` on every process and agrees on the outcome: -1 to go on, else
// the exit status. --help and its kind print what they ask for (the leader speaks for all), status 0;
// a refused line is bad input like any other, one line "PROGRAM: error: ..." naming the option,
// status 1 (CLI11's own form was two lines and a status of 101 to 114). Under MPI a rank whose line
// alone is refused, or alone asks for --help (mpirun's `A : B` form), ends the job at once, named,
// where the others used to wait for it until their time-out, or pair unlike collectives.
inline int parse(CLI::App& app, int argc, char** argv) {
    arguments_read().assign(argv + 1, argv + argc);
    std::optional<int> help;
    std::ostringstream help_out, help_err;
    std::string refused;
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) help = app.exit(e, help_out, help_err);
        else refused = std::string(e.what()) + " (see --help)";
    }
    try {
        together([&] { if (!refused.empty()) throw Error(refused); }, "reading the command line");
        agree(help ? "asked for --help or --version" : "did not ask for --help or --version", "comparing --help",
              [](const std::string& mine, const std::string& leaders) {
                  return "it " + mine + ", rank 0 " + leaders.substr(0, leaders.find(" for"));
              });
    } catch (const std::exception& e) {
        print_error(e);
        return 1;
    }
    if (!help) return -1;
    if (leader()) {
        std::fputs(help_out.str().c_str(), stdout);
        std::fputs(help_err.str().c_str(), stderr);
    }
    return *help;
}

// The results of the runs 0..count-1 on the leader, in run order (empty elsewhere), from each
// process's results of its share: results[k] is run mine[k]'s, mine = share(count).
std::vector<std::string> gather_runs(std::size_t count, const std::vector<std::size_t>& mine,
                                     std::vector<std::string> results);

// A sweep of independent runs 0..count-1, each run whole on one process (its share): `run(i)` returns
// run i's result, and the leader is handed every result in run order, `take(i, result)`: in one
// process as each run ends, under MPI once every rank has run its share. A run that throws on any
// process fails the sweep on all (`together`, named `name`).
void sweep(std::size_t count, const std::function<std::string(std::size_t)>& run,
           const std::function<void(std::size_t, const std::string&)>& take, const std::string& name);

}  // namespace cellrt::cli::cluster
