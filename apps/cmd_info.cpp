// `cellrt info SCENE [--accel KIND ...]`: scene facts, and with --accel the structure's build report.
// `cellrt info --params KIND`: the structure's build parameters (name, default, range, meaning) and
// traversals, from the table that validates them.
#include <cstdio>

#include "cellrt/device.hpp"
#include "cellrt/error.hpp"
#include "cellrt/scene.hpp"
#include "cli.hpp"

namespace cellrt::cli {
namespace {

void print_params(const std::string& kind) {
    const ParamTable& table = accelerator_params(kind);
    std::printf("%s parameters (-P NAME=VALUE):\n\n", kind.c_str());
    if (table.empty()) std::printf("(none)\n");
    else std::printf("%s", param_table_markdown(table).c_str());
    std::string traversals;
    for (const std::string& t : accelerator_traversals(kind)) traversals += (traversals.empty() ? "" : ", ") + t;
    std::printf("\n%s traversals (--traversal; the first is the default): %s\n", kind.c_str(), traversals.c_str());
}

void print_scene(const Scene& scene, double load_seconds) {
    const Box3 b = scene.bounds();
    std::printf("scene            %s\n", scene.name.c_str());
    std::printf("triangles        %zu\n", scene.triangles.size());
    std::printf("bounds           (%g, %g, %g) - (%g, %g, %g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    std::printf("memory           %.2f MiB\n",
                static_cast<double>(scene.triangles.size() * sizeof(Triangle)) / (1024.0 * 1024.0));
    std::printf("load time        %.3f s\n", load_seconds);
    std::printf("image            %dx%d\n", scene.width, scene.height);
}

// `info --device cuda`: the GPU's name and figures, or one line saying there is none.
bool print_device() {
    const DeviceInfo d = cuda_device_info();
    if (!d.present) {
        std::printf("cuda: no device (%s)\n", d.reason.c_str());
        return false;
    }
    std::printf("cuda             %s, compute capability %d.%d, %d multiprocessors, %.1f GiB, %zu KiB shared "
                "memory per block\n",
                d.name.c_str(), d.compute_major, d.compute_minor, d.multiprocessors,
                static_cast<double>(d.memory_bytes) / (1024.0 * 1024.0 * 1024.0), d.shared_memory_per_block / 1024);
    return true;
}

// The exit status of `info --device cuda` when there is no device, apart from errors' 1 (docs/GPU.md).
constexpr int kNoDevice = 3;

}  // namespace

Runner add_info(CLI::App& app) {
    struct Options {
        std::string scene;
        std::string params;
        AccelOptions accel;
    };
    auto o = std::make_shared<Options>();
    auto* cmd = app.add_subcommand("info", "Print scene facts; with --accel, build the structure and print its report");
    cmd->add_option("scene", o->scene, scene_help());
    cmd->add_option("--params", o->params, "Print the build parameters and traversals of this structure, then stop")
        ->check(CLI::IsMember(accelerator_kinds()));
    o->accel.add_to(*cmd, true, true);
    return [o] {
        if (!o->params.empty()) {
            // It prints a table and stops: a scene or a structure beside it would be ignored.
            if (!o->scene.empty() || !o->accel.kind.empty() || o->accel.describes_structure() ||
                o->accel.device != "cpu")
                throw Error("info: --params KIND prints that structure's parameters and nothing else: give it alone");
            print_params(o->params);
            return 0;
        }
        if (o->accel.device == "cuda" && !print_device()) return kNoDevice;
        if (o->scene.empty()) {
            if (o->accel.device == "cuda") return 0;
            throw Error("info: give a scene, --params KIND or --device cuda");
        }
        if (o->accel.kind.empty() && o->accel.describes_structure())
            throw Error("info: --traversal, --simd, -P and --threads describe a structure: give --accel too");
        if (!o->accel.kind.empty()) check_structure(o->accel);
        Timer load_timer;
        const Scene scene = load_scene(o->scene);
        print_scene(scene, load_timer.seconds());
        if (!o->accel.kind.empty())
            print_stats(build_structure(scene.triangles, o->accel.config(), o->accel)->stats());
        return 0;
    };
}

}  // namespace cellrt::cli
