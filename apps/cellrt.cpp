// The cellrt program and cellrt-mpi (the same commands over MPI ranks, apps/cluster.hpp): one subcommand
// per file (cmd_*.cpp), registered here.
#include <csignal>
#include <cstdio>
#include <exception>

#include <unistd.h>

#include "cellrt/error.hpp"
#include "cellrt/version.hpp"
#include "core/files.hpp"
#include "cli.hpp"
#include "cluster.hpp"

namespace {
// Whether an interrupt outside a frame says so: not under MPI, where mpirun ends the other ranks so
// when one fails (its error is the one line to read) and forwards a Ctrl-C to every rank.
bool g_say_interrupted = true;

// Only async-signal-safe calls: the atomics are lock-free, write and _exit are the system's.
extern "C" void on_interrupt(int) {
    cellrt::cli::g_cancel.store(true);
    if (cellrt::cli::g_cancellable.load()) return;
    static const char message[] = "cellrt: error: interrupted\n";
    if (g_say_interrupted) {
        [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, message, sizeof message - 1);
    }
    _exit(130);
}

int run(int argc, char** argv) {
    using namespace cellrt;
    CLI::App app{"cellrt: kd-tree and BIH ray tracing kernels after 'Data structures for ray tracing on Cell "
                 "architecture' (M. Hapala)"};
    app.require_subcommand(0, 1);
    app.set_version_flag("--version", std::string(cli::cluster::program()) + " " + CELLRT_VERSION_STRING);
    // The first command is the default: `cellrt` alone renders the default scene.
    const std::vector<cli::Runner> runners = {cli::add_render(app), cli::add_info(app), cli::add_profile(app),
                                              cli::add_cache_study(app)};
    cli::cluster::strict_numbers(app);
    if (const int status = cli::cluster::parse(app, argc, argv); status >= 0) return status;
    const auto subcommands = app.get_subcommands({});
    std::size_t chosen = 0;
    for (std::size_t i = 0; i < subcommands.size(); ++i)
        if (*subcommands[i]) chosen = i;
    g_say_interrupted = cli::cluster::ranks() == 1;
    std::signal(SIGINT, on_interrupt);
    std::signal(SIGTERM, on_interrupt);
    set_write_cancel(&cli::g_cancel);  // a signal before a wait for a pipe's reader ends it too
    try {
        // Under MPI only the commands whose work splits over the ranks run (docs/DISTRIBUTED.md).
        static const char* const kNames[] = {"render", "info", "profile", "cache-study"};
        cli::cluster::together([&] {
            if (cli::cluster::ranks() > 1 && (chosen == 1 || chosen == 2))
                throw Error(std::string(kNames[chosen]) + " runs in one process: run it with cellrt, not under mpirun");
        }, "choosing the command");
        // Ranks started with other commands (mpirun's `A : B`) would pair unlike collectives (found by
        // review, 2026-12-07).
        cli::cluster::agree(kNames[chosen], "comparing the commands", [](const std::string& mine, const std::string& leaders) {
            return "it runs " + mine + ", rank 0 " + leaders;
        });
        const int status = runners.at(chosen)();
        // A signal in a Cancellable section after its last poll (during the writing of the outputs,
        // which finished whole) still ends the run as interrupted (found by review, 2026-12-07).
        if (status == 0 && cli::g_cancel.load()) throw Error("interrupted (the outputs were written whole)");
        return status;
    } catch (const Error& e) {
        cli::cluster::print_error(e);
        return cli::g_cancel.load() ? 130 : 1;
    } catch (const std::bad_alloc&) {
        cli::cluster::print_error(Error("out of memory"));
        return 1;
    } catch (const std::exception& e) {
        // What the library did not turn into a cellrt::Error where it was thrown (each one found is
        // a bug, fixed there) still ends with one line and status 1, not in std::terminate.
        cli::cluster::print_error(e);
        return 1;
    }
}

}  // namespace

int main(int argc, char** argv) {
    try {
        cellrt::cli::cluster::start(argc, argv, "cellrt");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cellrt: error: %s\n", e.what());
        return 1;
    }
    return cellrt::cli::cluster::finish(cellrt::cli::cluster::flushed(run(argc, argv)));
}
