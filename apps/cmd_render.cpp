// `cellrt render [SCENE] ...`: one primary ray per pixel and the rays its shading casts (one shadow
// ray per hit; or AO rays; or a diffuse bounce), to PNG or PFM;
// with --local-store through the local-store model (docs/LOCALSTORE.md), whose cache statistics and
// modelled cycles are printed at the end.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <string>
#include <string_view>

#include "accel/local_store_registry.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cellrt/loaders.hpp"
#include "core/files.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "cli.hpp"
#include "cluster.hpp"

namespace cellrt::cli {
namespace {

// --local-store and the options that configure it.
struct LocalStoreOptions {
    bool enabled = false;
    std::string node_cache = LocalStoreConfig{}.node_cache.to_string();
    std::string tri_cache = LocalStoreConfig{}.triangle_cache.to_string();
    std::string access = "sync";
    bool no_retouch = false;
    int kib = static_cast<int>(LocalStoreConfig{}.budget_bytes / 1024);
    std::vector<CLI::Option*> dependent;  // options that mean nothing without --local-store

    void add_to(CLI::App& cmd) {
        cmd.add_flag("--local-store", enabled, "Trace through the local-store model: software caches in a per-worker "
                                               "local store, modelled cycles (docs/LOCALSTORE.md)");
        dependent = {
            cmd.add_option("--node-cache", node_cache, "Node cache LINExSETS[xWAYS]: line 16..4096 B, sets a power "
                                                       "of two, ways 1 or 4")
                ->capture_default_str(),
            cmd.add_option("--tri-cache", tri_cache, "Triangle cache LINExSETS[xWAYS]")->capture_default_str(),
            cmd.add_option("--cache-access", access, "sync (stall on a miss) or async (touch children, wait later)")
                ->capture_default_str(),
            cmd.add_flag("--no-retouch", no_retouch, "async: wait without touching again (shows the study's "
                                                     "stale-line artifact)"),
            cmd.add_option("--local-store-kib", kib, "Local store budget in KiB (16..16384)")->capture_default_str(),
        };
    }

    // The model's configuration for packets of `packet` x `packet` rays (a valid packet edge); throws
    // naming the option at fault.
    LocalStoreConfig config(int packet) const {
        if (!enabled) {
            for (const CLI::Option* opt : dependent)
                if (opt->count() > 0) throw Error(opt->get_name() + " needs --local-store");
            return {};
        }
        LocalStoreConfig c;
        c.node_cache = parse_cache_layout("--node-cache", node_cache);
        c.triangle_cache = parse_cache_layout("--tri-cache", tri_cache);
        c.access = parse_cache_access("--cache-access", access);
        if (no_retouch && c.access != CacheAccess::async) throw Error("--no-retouch needs --cache-access async");
        c.retouch = !no_retouch;
        if (kib < 16 || kib > 16384)
            throw Error("--local-store-kib " + std::to_string(kib) + " must lie in [16, 16384]");
        c.budget_bytes = static_cast<std::size_t>(kib) * 1024;
        check_packet_fits(packet, c.budget_bytes, "; --local-store-kib raises the budget");
        c.batch_rays = static_cast<std::size_t>(packet) * packet;
        return c;
    }
};

// The library's error for what the user gave as `option`, under the option's name: the library speaks
// of what the value means, the user typed the option.
Error option_error(const std::string& option, const Error& e) { return Error(option + ": " + e.what()); }

// --shading and --ao-samples; `ao_samples_given` is whether the user typed the latter, which means
// nothing for another shading.
ShadingOptions parse_shading_options(const std::string& shading, int ao_samples, const CLI::Option& ao_samples_given) {
    ShadingOptions s;
    try {
        s.shading = parse_shading(shading);
    } catch (const Error& e) {
        throw option_error("--shading", e);
    }
    if (ao_samples_given.count() > 0 && s.shading != Shading::ao) throw Error("--ao-samples needs --shading ao");
    if (ao_samples < 1 || ao_samples > kMaxAoSamples)
        throw Error("--ao-samples " + std::to_string(ao_samples) + " must lie in [1, " + std::to_string(kMaxAoSamples) +
                    "]");
    s.ao_samples = ao_samples;
    return s;
}

double mib(std::uint64_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

// Whether the cache was read at all: a frame whose rays never read it (a camera looking away from the
// scene) has no hit ratio, and 0 % would read as the worst (as cache-study writes it: found by audit,
// 2026-12-07).
bool was_read(const CacheStats& s) { return s.hits + s.misses > 0; }

void print_cache(const char* name, const CacheLayout& layout, const CacheStats& s) {
    char ratio[32] = "no reads";
    if (was_read(s)) std::snprintf(ratio, sizeof ratio, "%.2f %% hits", 100.0 * s.hit_ratio());
    std::printf("  %-15s %-9s %s (%llu hits, %llu misses, %llu prefetches), %.2f MiB in, %llu evictions, "
                "%llu stale waits\n",
                name, layout.to_string().c_str(), ratio, static_cast<unsigned long long>(s.hits),
                static_cast<unsigned long long>(s.misses), static_cast<unsigned long long>(s.prefetches), mib(s.bytes),
                static_cast<unsigned long long>(s.evictions), static_cast<unsigned long long>(s.stale_waits));
}

void print_local_store(const LocalStoreAccelerator& accel) {
    const LocalStoreConfig& c = accel.local_store_config();
    const LocalStoreStats s = accel.local_store_stats();
    std::size_t used = 0;
    for (const auto& a : accel.local_store_allocations()) used += a.bytes;
    std::printf("local store: %zu of %zu bytes used, %s access%s, %u worker(s), %llu rays in %llu batches\n", used,
                c.budget_bytes, to_string(c.access),
                c.access == CacheAccess::async && !c.retouch ? " without re-touch" : "",
                s.workers, static_cast<unsigned long long>(s.rays), static_cast<unsigned long long>(s.batches));
    print_cache("node cache", c.node_cache, s.node_cache);
    print_cache("triangle cache", c.triangle_cache, s.triangle_cache);
    std::printf("  modelled        %llu cycles (%.2f cycles/ray, %.1f %% waiting for transfers): %.3f ms at %.1f GHz "
                "on one worker, %.3f ms for the busiest of %u\n",
                static_cast<unsigned long long>(s.cycles), s.cycles_per_ray(),
                s.cycles ? 100.0 * static_cast<double>(s.stall_cycles) / static_cast<double>(s.cycles) : 0.0,
                1e3 * c.cost.seconds(s.cycles), c.cost.clock_ghz, 1e3 * c.cost.seconds(s.frame_cycles), s.workers);
}

nlohmann::json cache_json(const CacheLayout& layout, const CacheStats& s) {
    return {{"layout", layout.to_string()}, {"line_bytes", layout.line_bytes}, {"sets", layout.sets},
            {"ways", layout.ways},          {"hit_ratio", was_read(s) ? nlohmann::json(s.hit_ratio()) : nlohmann::json()},
            {"hits", s.hits},
            {"misses", s.misses},           {"prefetches", s.prefetches},      {"touch_hits", s.touch_hits},
            {"bytes", s.bytes},             {"evictions", s.evictions},        {"stale_waits", s.stale_waits}};
}

nlohmann::json local_store_json(const LocalStoreAccelerator& accel) {
    const LocalStoreConfig& c = accel.local_store_config();
    const LocalStoreStats s = accel.local_store_stats();
    nlohmann::json allocations = nlohmann::json::array();
    for (const auto& a : accel.local_store_allocations()) allocations.push_back({{"what", a.what}, {"bytes", a.bytes}});
    const CostModel& m = c.cost;
    return {{"budget_bytes", c.budget_bytes},
            {"allocations", allocations},
            {"access", to_string(c.access)},
            {"retouch", c.retouch},
            {"node_cache", cache_json(c.node_cache, s.node_cache)},
            {"triangle_cache", cache_json(c.triangle_cache, s.triangle_cache)},
            {"workers", s.workers},
            {"rays", s.rays},
            {"batches", s.batches},
            {"cycles", s.cycles},
            {"stall_cycles", s.stall_cycles},
            {"busiest_worker_cycles", s.frame_cycles},
            {"cycles_per_ray", s.cycles_per_ray()},
            {"modelled_seconds_one_worker", m.seconds(s.cycles)},
            {"modelled_seconds_busiest_worker", m.seconds(s.frame_cycles)},
            {"cost_model",
             {{"clock_ghz", m.clock_ghz}, {"dma_latency", m.dma_latency}, {"bytes_per_cycle", m.bytes_per_cycle},
              {"dma_queue", m.dma_queue}, {"ls_access", m.ls_access}, {"cache_lookup", m.cache_lookup},
              {"miss_handling", m.miss_handling}, {"ray_setup", m.ray_setup}, {"inner_node", m.inner_node},
              {"leaf", m.leaf}, {"triangle_test", m.triangle_test}, {"branch_miss", m.branch_miss},
              {"branched_miss_rate", m.branched_miss_rate}, {"branchless_extra", m.branchless_extra}}}};
}

}  // namespace

Runner add_render(CLI::App& app) {
    struct Options {
        std::string scene = default_scene_spec();
        std::string size, out = "cellrt.png", dispatch = "pull", shading = "direct";
        bool overwrite = false, pin = false;
        int packet = RenderOptions{}.packet;
        int ao_samples = ShadingOptions{}.ao_samples;
        AccelOptions accel;
        LocalStoreOptions local_store;
        std::string stats;
    };
    auto o = std::make_shared<Options>();
    auto* cmd = app.add_subcommand("render", "Render a scene to an image (primary rays and those their shading casts)");
    cmd->add_option("scene", o->scene, scene_help())->capture_default_str();
    o->accel.add_to(*cmd, false, true);
    cmd->add_option("--size", o->size, "Image size WIDTHxHEIGHT (default: the view file's)")->check(non_empty());
    cmd->add_option("-o,--output", o->out, "Output image: .png (sRGB) or .pfm (exact floats)")
        ->capture_default_str()
        ->check(non_empty());
    cmd->add_flag("--overwrite", o->overwrite, "Replace the output file if it exists");
    cmd->add_option("--shading", o->shading,
                    "direct: one shadow ray per hit (the study's); ao: ambient occlusion; diffuse: one bounce lit "
                    "by the light")
        ->capture_default_str();
    auto* ao_samples = cmd->add_option("--ao-samples", o->ao_samples, "AO rays per hit (1.." +
                                       std::to_string(kMaxAoSamples) + "), with --shading ao")
                           ->capture_default_str();
    cmd->add_option("--packet", o->packet, "Packet edge P: workers trace P x P rays at a time")->capture_default_str();
    cmd->add_option("--dispatch", o->dispatch,
                    "How packets reach workers: pull (each worker a run of packets, stealing when done) or "
                    "mailbox (the study's master)")
        ->capture_default_str();
    cmd->add_flag("--pin", o->pin, "Pin worker i to core i (mailbox: the master to core 0, worker i to core i + 1)");
    o->local_store.add_to(*cmd);
    cmd->add_option("--stats", o->stats, "Write the run's figures (each worker's load, the local store's) as JSON to FILE")
        ->check(non_empty());
    cluster::add_render_options(*cmd);
    return [o, ao_samples] {
        // Under MPI each step runs on every rank, and a step that fails on one fails on all
        // (cluster.hpp); rank 0 alone checks and writes the outputs.
        ShadingOptions shading;
        LocalStoreConfig local_store;
        // The model runs the single-ray kernels: SIMD packets are off unless asked for, and then refused.
        const auto modelled_config = [&] {
            AccelConfig config = o->accel.config();
            if (o->accel.simd_option->count() == 0 && !o->accel.simd_named()) config.simd = "off";
            return config;
        };
        cluster::together([&] {
            shading = parse_shading_options(o->shading, o->ao_samples, *ao_samples);
            if (o->packet < 1 || o->packet > kMaxPacket)
                throw Error("--packet " + std::to_string(o->packet) + " must lie in [1, " + std::to_string(kMaxPacket) +
                            "]");
            local_store = o->local_store.config(o->packet);
            // At any rank count: one rank's tiles change the order of the packets, and so the caches'
            // figures (found by audit, 2026-12-07: `-np 1` gave other figures without a word).
            if (o->local_store.enabled && cluster::distributed())
                throw Error("--local-store models one process's workers over the whole frame: run it with cellrt, not "
                            "cellrt-mpi");
            // Every option that does not need the scene, before it is loaded.
            if (!o->size.empty()) parse_image_size("--size", o->size);
            try {
                parse_dispatch(o->dispatch);
            } catch (const Error& e) {
                throw option_error("--dispatch", e);
            }
            if (o->local_store.enabled && o->accel.device != "cpu")
                throw Error("--local-store models the Cell's local store on the CPU; it does not run with --device " +
                            o->accel.device);
            if (o->local_store.enabled) {
                check_names(o->accel);
                // The library's refusal is of the budget the caches and the batch exceed: named by the
                // option that sets it (found by audit, 2026-12-07).
                try {
                    make_local_store_accelerator(std::span<const Triangle>(&kOneTriangle, 1), modelled_config(),
                                                 local_store);
                } catch (const Error& e) {
                    if (std::string_view(e.what()).starts_with("local store: "))
                        throw option_error("--local-store-kib " + std::to_string(o->local_store.kib), e);
                    throw;
                }
            } else {
                check_structure(o->accel);
            }
            if (cluster::leader()) {
                check_output_file(o->out, o->overwrite);
                if (!o->stats.empty()) check_output_file(o->stats, o->overwrite);
                check_distinct_files({{"-o", o->out}, {"--stats", o->stats}}, scene_files(o->scene));
            }
        }, "checking the options");
        Timer load_timer;
        const Scene scene = cluster::load_scene(o->scene);
        const double load_s = load_timer.seconds();
        RenderOptions ro;
        std::unique_ptr<LocalStoreAccelerator> modelled;
        std::unique_ptr<Accelerator> direct;
        cluster::together([&] {
            ro.width = scene.width;
            ro.height = scene.height;
            if (!o->size.empty()) std::tie(ro.width, ro.height) = parse_image_size("--size", o->size);
            ro.threads = o->accel.threads;
            ro.packet = o->packet;
            ro.shading = shading;
            try {
                ro.dispatch = parse_dispatch(o->dispatch);
            } catch (const Error& e) {
                throw option_error("--dispatch", e);
            }
            ro.pin = o->pin;
            ro.cancel = &g_cancel;
            if (o->local_store.enabled) {
                modelled = make_local_store_accelerator(scene.triangles, modelled_config(), local_store);
            } else {
                direct = build_structure(scene.triangles, o->accel.config(), o->accel);
            }
        }, "building the structure");
        const Accelerator& accel = modelled ? *modelled : *direct;
        Progress progress;
        if (cluster::leader()) ro.progress = [&](std::size_t d, std::size_t t) { progress(d, t); };
        RenderStats rs;
        cluster::Frame frame;
        nlohmann::json ranks_report = nlohmann::json::object();
        // The frame's wall time from its memory to its last pixel: what cellrt-mpi's render seconds
        // span (its frame, window and renderers included), where the plain render's figure is the
        // tracing alone; the two programs compare on this one (docs/DISTRIBUTED.md).
        const Cancellable cancellable;  // the frame, and the writing of its files
        Timer frame_timer;
        cluster::render(scene, accel, ro, lower_extension(o->out) == ".png", frame, rs, ranks_report);
        const double frame_s = frame_timer.seconds();
        progress.finish();
        if (!cluster::leader()) return 0;
        // Ctrl-C after the last packet, while the frame was gathered, still ends the run with no file
        // (found by audit, 2026-12-07: it was ignored). One during the writes is seen after them, by
        // cellrt.cpp's run: the files are then whole, and the status 130.
        if (g_cancel) throw Error("render cancelled");
        if (const Image* image = std::get_if<Image>(&frame)) write_image(*image, o->out, o->overwrite);
        else write_png(std::get<Srgb8Image>(frame), o->out, o->overwrite);
        const AccelStats st = accel.stats();
        std::printf("%s: %zu triangles, %dx%d, %s, load %.3f s, build %.3f s, render %.3f s (%.2f Mrays/s) -> %s\n",
                    scene.name.c_str(), scene.triangles.size(), ro.width, ro.height, st.name.c_str(), load_s,
                    st.build_seconds, rs.seconds,
                    static_cast<double>(rs.primary_rays + rs.secondary_rays) / rs.seconds * 1e-6, o->out.c_str());
        if (modelled) print_local_store(*modelled);
        if (!o->stats.empty()) {
            nlohmann::json j = {{"scene", scene.name},          {"triangles", scene.triangles.size()},
                                {"width", ro.width},            {"height", ro.height},
                                {"structure", st.name},         {"threads", rs.workers.size()},
                                {"packet", ro.packet},          {"primary_rays", rs.primary_rays},
                                {"shading", to_string(shading.shading)}, {"secondary_rays", rs.secondary_rays},
                                {"build_seconds", st.build_seconds},
                                {"render_seconds", rs.seconds}, {"frame_seconds", frame_s},
                                {"figures", nlohmann::json::object()}};
            if (shading.shading == Shading::ao) j["ao_samples"] = shading.ao_samples;
            for (const auto& [k, v] : st.figures()) j["figures"][k] = v;
            // Each worker's share of the frame (docs/SCALING.md): the packets it traced, the time it
            // spent tracing them, and when it started and finished, from the frame's start.
            j["dispatch"] = to_string(ro.dispatch);
            j["workers"] = nlohmann::json::array();
            for (const WorkerLoad& w : rs.workers)
                j["workers"].push_back({{"packets", w.packets},
                                        {"busy_seconds", w.busy_seconds},
                                        {"started_seconds", w.started_seconds},
                                        {"finished_seconds", w.finished_seconds}});
            if (modelled) j["local_store"] = local_store_json(*modelled);
            j.update(ranks_report);  // under MPI: the tiles, and what each rank did
            write_file_atomically(o->stats, json_report(j), o->overwrite);
        }
        return 0;
    };
}

}  // namespace cellrt::cli
