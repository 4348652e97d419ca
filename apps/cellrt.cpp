// The cellrt command-line program: one subcommand per file (cmd_*.cpp), registered here.
#include <csignal>
#include <cstdio>
#include <exception>

#include "cellrt/error.hpp"
#include "cli.hpp"

namespace {
extern "C" void on_interrupt(int) { cellrt::cli::g_cancel.store(true); }
}  // namespace

int main(int argc, char** argv) {
    using namespace cellrt;
    CLI::App app{"cellrt: kd-tree and BIH ray tracing kernels after 'Data structures for ray tracing on Cell "
                 "architecture' (M. Hapala)"};
    app.require_subcommand(0, 1);
    // The first command is the default: `cellrt` alone renders the default scene.
    const std::vector<cli::Runner> runners = {cli::add_render(app), cli::add_info(app), cli::add_profile(app),
                                              cli::add_cache_study(app)};
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    const auto subcommands = app.get_subcommands({});
    std::size_t chosen = 0;
    for (std::size_t i = 0; i < subcommands.size(); ++i)
        if (*subcommands[i]) chosen = i;
    std::signal(SIGINT, on_interrupt);
    std::signal(SIGTERM, on_interrupt);
    try {
        return runners.at(chosen)();
    } catch (const Error& e) {
        std::fprintf(stderr, "cellrt: error: %s\n", e.what());
        return cli::g_cancel.load() ? 130 : 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "cellrt: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        // What the library did not turn into a cellrt::Error where it was thrown (each one found is
        // a bug, fixed there) still ends with one line and status 1, not in std::terminate.
        std::fprintf(stderr, "cellrt: error: %s\n", e.what());
        return 1;
    }
}
