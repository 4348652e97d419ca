// `cellrt render [SCENE] ...`: one primary ray per pixel and one shadow ray per hit, to PNG or PFM.
#include <cstdio>

#include "cellrt/builtin.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "cli.hpp"

namespace cellrt::cli {

Runner add_render(CLI::App& app) {
    struct Options {
        std::string scene = default_scene_spec();
        std::string size, out = "cellrt.png", dispatch = "pull";
        bool overwrite = false, pin = false;
        int packet = RenderOptions{}.packet;
        AccelOptions accel;
    };
    auto o = std::make_shared<Options>();
    auto* cmd = app.add_subcommand("render", "Render a scene to an image (primary + one shadow ray per hit)");
    cmd->add_option("scene", o->scene, scene_help())->capture_default_str();
    o->accel.add_to(*cmd, false);
    cmd->add_option("--size", o->size, "Image size WIDTHxHEIGHT (default: the view file's)");
    cmd->add_option("-o,--output", o->out, "Output image: .png (sRGB) or .pfm (exact floats)")->capture_default_str();
    cmd->add_flag("--overwrite", o->overwrite, "Replace the output file if it exists");
    cmd->add_option("--packet", o->packet, "Packet edge P: workers trace P x P rays at a time")->capture_default_str();
    cmd->add_option("--dispatch", o->dispatch, "How packets reach workers: pull (shared counter) or mailbox (the "
                                               "study's master)")
        ->capture_default_str();
    cmd->add_flag("--pin", o->pin, "Pin worker i to core i");
    return [o] {
        Timer load_timer;
        const Scene scene = load_scene(o->scene);
        const double load_s = load_timer.seconds();
        RenderOptions ro;
        ro.width = scene.width;
        ro.height = scene.height;
        if (!o->size.empty()) std::tie(ro.width, ro.height) = parse_size("--size", o->size);
        ro.threads = o->accel.threads;
        ro.packet = o->packet;
        ro.dispatch = parse_dispatch(o->dispatch);
        ro.pin = o->pin;
        ro.cancel = &g_cancel;
        const auto accel = make_accelerator(scene.triangles, o->accel.config());
        Progress progress;
        ro.progress = [&](std::size_t d, std::size_t t) { progress(d, t); };
        RenderStats rs;
        const Image image = render(scene, *accel, ro, &rs);
        write_image(image, o->out, o->overwrite);
        const AccelStats st = accel->stats();
        std::printf("%s: %zu triangles, %dx%d, %s, load %.3f s, build %.3f s, render %.3f s (%.2f Mrays/s) -> %s\n",
                    scene.name.c_str(), scene.triangles.size(), ro.width, ro.height, st.name.c_str(), load_s,
                    st.build_seconds, rs.seconds,
                    static_cast<double>(rs.primary_rays + rs.shadow_rays) / rs.seconds * 1e-6, o->out.c_str());
        return 0;
    };
}

}  // namespace cellrt::cli
