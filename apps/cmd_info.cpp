// `cellrt info SCENE [--accel KIND ...]`: scene facts, and with --accel the structure's build report.
#include <cstdio>

#include "cellrt/scene.hpp"
#include "cli.hpp"

namespace cellrt::cli {

Runner add_info(CLI::App& app) {
    struct Options {
        std::string scene;
        AccelOptions accel;
    };
    auto o = std::make_shared<Options>();
    auto* cmd = app.add_subcommand("info", "Print scene facts; with --accel, build the structure and print its report");
    cmd->add_option("scene", o->scene, scene_help())->required();
    o->accel.add_to(*cmd, true);
    return [o] {
        Timer load_timer;
        const Scene scene = load_scene(o->scene);
        const double load_s = load_timer.seconds();
        const Box3 b = scene.bounds();
        std::printf("scene            %s\n", scene.name.c_str());
        std::printf("triangles        %zu\n", scene.triangles.size());
        std::printf("bounds           (%g, %g, %g) - (%g, %g, %g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
        std::printf("memory           %.2f MiB\n",
                    static_cast<double>(scene.triangles.size() * sizeof(Triangle)) / (1024.0 * 1024.0));
        std::printf("load time        %.3f s\n", load_s);
        std::printf("image            %dx%d\n", scene.width, scene.height);
        if (!o->accel.kind.empty()) print_stats(make_accelerator(scene.triangles, o->accel.config())->stats());
        return 0;
    };
}

}  // namespace cellrt::cli
