// Pieces shared by the subcommands of the cellrt program. Each subcommand lives in a file of its own
// (cmd_*.cpp) and registers itself with add_*(): it adds its options to the program and returns the
// function that runs it once the command line is parsed.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cellrt/accel.hpp"
#include "core/timer.hpp"

namespace cellrt::cli {

using Runner = std::function<int()>;

Runner add_render(CLI::App& app);
Runner add_info(CLI::App& app);
Runner add_profile(CLI::App& app);
Runner add_cache_study(CLI::App& app);

// Set by SIGINT/SIGTERM inside a Cancellable section (a frame, a cache study's runs, the writing of
// results), which stops at the next packet or run, leaves no partial output, and ends with status
// 130. Outside one (a load, a build, `info`, `profile`) the signal ends the program at once with
// status 130 (cellrt.cpp's on_interrupt): those leave nothing behind, and polled nowhere they ran to
// the end and exited 0 (found by audit, 2026-12-07: `timeout` could not stop a long build).
extern std::atomic<bool> g_cancel;
extern std::atomic<bool> g_cancellable;

struct Cancellable {
    Cancellable() { g_cancellable.store(true); }
    ~Cancellable() { g_cancellable.store(false); }
    Cancellable(const Cancellable&) = delete;
    Cancellable& operator=(const Cancellable&) = delete;
};

// The scene argument's help text (view file, mesh or builtin:NAME).
std::string scene_help();

// --accel, --traversal, --simd, -P NAME=VALUE and --threads, shared by every command that builds a
// structure, and --device where the command offers the GPU. SIMD packets are the default; naming a
// --traversal (a single-ray kernel) or --device cuda without --simd turns them off.
struct AccelOptions {
    std::string kind = "kd";
    std::string traversal;
    std::string simd = "auto";
    std::string device = "cpu";
    std::vector<std::string> params;
    unsigned threads = 0;
    CLI::Option *simd_option = nullptr, *traversal_option = nullptr, *params_option = nullptr,
                *threads_option = nullptr;

    void add_to(CLI::App& cmd, bool kind_optional, bool with_device = false);
    AccelConfig config() const;
    // Whether --traversal, --simd, -P or --threads was given: they describe a structure.
    bool describes_structure() const;
    // Whether --accel's string names a SIMD set ("kd+sse").
    bool simd_named() const;
    // The option the SIMD set came from, as the user typed it: --simd, or --accel 'kd+sse'.
    std::string simd_source() const;
};

// The structure for `config` (made from `options`), as make_accelerator builds it. Where it is refused
// and the library refuses the SIMD set too, the error is the option's that named the set: the library
// speaks of the set, the user typed the option (looked at only after a refusal: Embree ignores the
// set, and a bad one is no error for it). A traversal the structure does not run (a kd-tree's, with
// SIMD packets) is refused.
std::unique_ptr<Accelerator> build_structure(std::span<const Triangle> triangles, const AccelConfig& config,
                                             const AccelOptions& options);

// The structure `options` name, built over one triangle and thrown away: an unknown kind, traversal,
// parameter or SIMD set, or --device cuda without a GPU, is refused before a scene is loaded (found
// by audit, 2026-12-07: `render --size 0x0` or `--accel bogus` loaded a 5M-triangle scene first, and
// `info` printed half its report), in the words of the option that gave it.
void check_structure(const AccelOptions& options);

// The scene check_structure builds over: a structure's options are refused by it as by any scene's.
inline constexpr Triangle kOneTriangle{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}};

// options.config(), its kind and traversal checked against the library's and refused in the words of
// the option that gave them (what check_structure does before it builds).
AccelConfig check_names(const AccelOptions& options);

void print_stats(const AccelStats& s);

// A CLI11 check that refuses an empty value (an option given as "" means no default).
CLI::Validator non_empty();

// Refuses a --threads of more than the library's kMaxWorkers.
void check_threads(unsigned threads);

// Refuses a --packet whose P x P rays and their results do not fit a local store of `budget_bytes`
// (the library would refuse the batch after the scene is loaded, without naming the option), saying
// the largest that fits; `remedy` is appended to that, as "; --local-store-kib raises the budget".
void check_packet_fits(int packet, std::size_t budget_bytes, const std::string& remedy);

// A JSON report as written to a file: indented, ending in a newline, any byte that is not UTF-8 (of a
// file name, say) replaced by U+FFFD rather than failing once the work is done.
std::string json_report(const nlohmann::json& report);


// A one-line progress bar on stderr, shown only on a terminal and only once a render has run for a
// second.
class Progress {
public:
    Progress();
    ~Progress();
    void operator()(std::size_t done, std::size_t total);
    // Ends the bar's line, where one was drawn: before what the program prints next (the summary
    // used to follow the bar on its line).
    void finish();

private:
    bool enabled_;
    bool shown_ = false;
    std::size_t drawn_ = 0;  // the most packets drawn done: calls arrive out of order under pull dispatch
    Timer timer_;
    std::mutex mutex_;
};

}  // namespace cellrt::cli
