// The cellrt command-line program: render scenes, print scene and structure reports.
#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <unistd.h>

#include "cellrt/accel.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/timer.hpp"

namespace {

using namespace cellrt;

std::atomic<bool> g_cancel{false};
extern "C" void on_interrupt(int) { g_cancel.store(true); }

struct AccelOptions {
    std::string kind = "brute";
    std::string traversal;
    std::vector<std::string> params;
    unsigned threads = 0;

    void add_to(CLI::App& cmd, bool kind_optional) {
        std::string kinds;
        for (const auto& k : accelerator_kinds()) kinds += (kinds.empty() ? "" : "|") + k;
        if (kind_optional) kind.clear();
        cmd.add_option("--accel", kind, "Acceleration structure: " + kinds)->capture_default_str();
        cmd.add_option("--traversal", traversal, "Traversal variant (structure-specific; default: its first)");
        cmd.add_option("-P,--param", params, "Build parameter NAME=VALUE (repeatable; docs/PARAMETERS.md)");
        cmd.add_option("--threads", threads, "Worker and build threads (0: all cores)")->capture_default_str();
    }

    AccelConfig config() const {
        AccelConfig c;
        c.kind = kind;
        c.traversal = traversal;
        c.threads = threads;
        for (const std::string& p : params) {
            const auto eq = p.find('=');
            if (eq == std::string::npos || eq == 0) throw Error("--param '" + p + "' must have the form NAME=VALUE");
            c.params[p.substr(0, eq)] = p.substr(eq + 1);
        }
        return c;
    }
};

void print_stats(const AccelStats& s) {
    std::printf("structure        %s\n", s.name.c_str());
    std::printf("build time       %.3f s\n", s.build_seconds);
    std::printf("memory           %.2f MiB\n", static_cast<double>(s.memory_bytes) / (1024.0 * 1024.0));
    for (const auto& [k, v] : s.figures) std::printf("%-16s %s\n", k.c_str(), v.c_str());
}

// A one-line progress bar on stderr, shown only on a terminal and only once a render has run for
// a second.
class Progress {
public:
    Progress() : enabled_(::isatty(STDERR_FILENO)) {}
    void operator()(std::size_t done, std::size_t total) {
        if (!enabled_ || timer_.seconds() < 1.0) return;
        std::lock_guard lock(mutex_);
        const int width = 40, filled = static_cast<int>(width * done / total);
        std::fprintf(stderr, "\r[%s%s] %3zu%%", std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(),
                     100 * done / total);
        shown_ = true;
    }
    ~Progress() {
        if (shown_) std::fprintf(stderr, "\n");
    }

private:
    bool enabled_;
    bool shown_ = false;
    Timer timer_;
    std::mutex mutex_;
};

std::pair<int, int> parse_size(const std::string& text) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 1 || h < 1 || w > 65536 ||
        h > 65536)
        throw Error("--size '" + text + "' must be WIDTHxHEIGHT with both in [1, 65536]");
    return {w, h};
}

int run_render(const std::string& spec, const AccelOptions& accel_opts, const std::string& size, const std::string& out,
               bool overwrite) {
    Timer load_timer;
    const Scene scene = load_scene(spec);
    const double load_s = load_timer.seconds();
    RenderOptions ro;
    ro.width = scene.width;
    ro.height = scene.height;
    if (!size.empty()) std::tie(ro.width, ro.height) = parse_size(size);
    ro.threads = accel_opts.threads;
    ro.cancel = &g_cancel;
    const auto accel = make_accelerator(scene.triangles, accel_opts.config());
    Progress progress;
    ro.progress = [&](std::size_t d, std::size_t t) { progress(d, t); };
    RenderStats rs;
    const Image image = render(scene, *accel, ro, &rs);
    write_image(image, out, overwrite);
    const AccelStats st = accel->stats();
    std::printf("%s: %zu triangles, %dx%d, %s, load %.3f s, build %.3f s, render %.3f s (%.2f Mrays/s) -> %s\n",
                scene.name.c_str(), scene.triangles.size(), ro.width, ro.height, st.name.c_str(), load_s,
                st.build_seconds, rs.seconds, static_cast<double>(rs.primary_rays + rs.shadow_rays) / rs.seconds * 1e-6,
                out.c_str());
    return 0;
}

int run_info(const std::string& spec, const AccelOptions& accel_opts) {
    Timer load_timer;
    const Scene scene = load_scene(spec);
    const double load_s = load_timer.seconds();
    const Box3 b = scene.bounds();
    std::printf("scene            %s\n", scene.name.c_str());
    std::printf("triangles        %zu\n", scene.triangles.size());
    std::printf("bounds           (%g, %g, %g) - (%g, %g, %g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    std::printf("memory           %.2f MiB\n",
                static_cast<double>(scene.triangles.size() * sizeof(Triangle)) / (1024.0 * 1024.0));
    std::printf("load time        %.3f s\n", load_s);
    std::printf("image            %dx%d\n", scene.width, scene.height);
    if (!accel_opts.kind.empty()) {
        const auto accel = make_accelerator(scene.triangles, accel_opts.config());
        print_stats(accel->stats());
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"cellrt: kd-tree and BIH ray tracing kernels after 'Data structures for ray tracing on Cell "
                 "architecture'"};
    app.require_subcommand(0, 1);

    std::string scenes_help = "Scene: VIEW.json, MESH.obj, or builtin:NAME[?tris=N&seed=S] (";
    for (const auto& b : builtin_scenes()) scenes_help += b.name + " ";
    scenes_help += ")";

    std::string render_scene = default_scene_spec(), render_size, render_out = "cellrt.png";
    bool overwrite = false;
    AccelOptions render_accel;
    auto* render_cmd = app.add_subcommand("render", "Render a scene to an image (primary + one shadow ray per hit)");
    render_cmd->add_option("scene", render_scene, scenes_help)->capture_default_str();
    render_accel.add_to(*render_cmd, false);
    render_cmd->add_option("--size", render_size, "Image size WIDTHxHEIGHT (default: the view file's)");
    render_cmd->add_option("-o,--output", render_out, "Output image: .png (sRGB) or .pfm (exact floats)")
        ->capture_default_str();
    render_cmd->add_flag("--overwrite", overwrite, "Replace the output file if it exists");

    std::string info_scene;
    AccelOptions info_accel;
    auto* info_cmd = app.add_subcommand("info", "Print scene facts; with --accel, build it and print its report");
    info_cmd->add_option("scene", info_scene, scenes_help)->required();
    info_accel.add_to(*info_cmd, true);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    std::signal(SIGINT, on_interrupt);
    std::signal(SIGTERM, on_interrupt);
    try {
        if (*info_cmd) return run_info(info_scene, info_accel);
        return run_render(render_scene, render_accel, render_size, render_out, overwrite);
    } catch (const Error& e) {
        std::fprintf(stderr, "cellrt: error: %s\n", e.what());
        return g_cancel.load() ? 130 : 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "cellrt: error: out of memory\n");
        return 1;
    }
}
