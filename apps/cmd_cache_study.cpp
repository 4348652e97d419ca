// `cellrt cache-study SCENE... [-o DIR]`: the study's cache experiments (Hapala, section 5.2, Graphs
// 5-1 to 5-10) through the local-store model. For every scene, structure (kd, bih), traversal
// (branched, branchless) and access (sync, async), it sweeps the node cache's layout with the triangle
// cache fixed at 128 B x 128 sets (as the study did), then the triangle cache's layout with the node
// cache at the study's best for the structure, and writes one CSV row per run: hit ratios, bytes
// moved, modelled cycles, wall time. bench/plot_cache_study.py draws the graphs from the CSV; the best
// layouts are compared with the study's in best_layouts.md (docs/LOCALSTORE.md discusses them).
//
// Rays: those of one frame as the renderer traces them (workload.hpp), packet by packet: a packet's
// primary rays in the renderer's packet order (Morton order), then the shadow rays of their hits, of
// a sample of the packets: those whose column + row is a multiple of --sample. Each run is one worker
// tracing the sample in order, so its figures are reproducible; runs are spread over --threads
// threads.
//
// With --device cuda the same runs go to the GPU's memory mode (b) instead (docs/GPU.md): the study's
// caches in each block's shared memory, of the run's layouts and access (async: cp.async as the touch,
// the next read as the wait, with its re-touch). The frame's
// sampled rays are copied to the device once, each run's tree is built and copied there, and its
// primary and shadow rays are traced as two resident batches, one ray per thread. The CSV keeps its
// columns: hits and misses are the blocks' lookups summed (a torn read counts as a miss), bytes the
// lines filled, the cycle columns 0 (nothing is modelled) and frame_ms the kernels' own time (CUDA
// events) per ray times the frame's rays; best_layouts.md ranks by that time.
#include <algorithm>
#include <cstring>
#include <atomic>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <system_error>
#include <thread>
#include <type_traits>
#include <unistd.h>
#include <utility>

#include "accel/local_store_registry.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/device.hpp"
#include "cellrt/error.hpp"
#include "cellrt/loaders.hpp"
#include "core/csv.hpp"
#include "core/files.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/workload.hpp"
#include "cli.hpp"
#include "cluster.hpp"

namespace cellrt::cli {
namespace {

// Layouts swept for one cache: lines of 16 B to 4 KiB for several numbers of sets, direct-mapped and
// 4-way, up to the study's largest cache, 16 KiB. The sets include the study's best layouts (kd nodes
// 128 x 128, BIH nodes 256 x 64, triangles 1024 x 16).
std::vector<CacheLayout> swept_layouts() {
    constexpr std::size_t kMaxCapacity = 16 * 1024;
    std::vector<CacheLayout> out;
    const std::pair<std::uint32_t, std::vector<std::uint32_t>> families[] = {{1, {4, 16, 64, 128, 256}},
                                                                             {4, {1, 4, 16, 32}}};
    for (const auto& [ways, sets_list] : families)
        for (std::uint32_t sets : sets_list)
            for (std::uint32_t line = CacheLayout::kMinLine; line <= CacheLayout::kMaxLine; line *= 2)
                if (CacheLayout{line, sets, ways}.capacity() <= kMaxCapacity) out.push_back({line, sets, ways});
    return out;
}

// The study's best layouts (section 5.2), each 16 KiB direct-mapped: its results for the two trees it
// measured. A tree the study did not measure is swept with the kd-tree's.
CacheLayout study_node_layout(const std::string& structure) {
    static const std::map<std::string, CacheLayout> kStudyNodeLayouts{{"kd", {128, 128, 1}}, {"bih", {256, 64, 1}}};
    const auto it = kStudyNodeLayouts.find(structure);
    return it != kStudyNodeLayouts.end() ? it->second : kStudyNodeLayouts.at("kd");
}
constexpr CacheLayout kStudyTriangleLayout{1024, 16, 1};
// The triangle cache while the node cache is swept, as in the study.
constexpr CacheLayout kFixedTriangleLayout{128, 128, 1};

// The frame's packets whose column + row is a multiple of `sample`, traced as the renderer traces
// them (workload.hpp), with the hits of an exact kd-tree.
FrameRays sampled_frame(const Scene& scene, int width, int height, int packet, int sample) {
    const PacketGrid grid(width, height, packet);
    const auto columns = static_cast<std::size_t>(grid.columns());
    return frame_rays(scene, width, height, packet, *make_accelerator(scene.triangles, AccelConfig{"kd"}), {},
                      [&](std::size_t p) { return (p % columns + p / columns) % static_cast<std::size_t>(sample) == 0; });
}

struct Run {
    std::string structure, traversal, sweep;  // sweep: "node" or "triangle", the cache whose layout varies
    LocalStoreConfig config;
};

struct Result {
    LocalStoreStats stats;
    double wall_seconds = 0.0;
    double kernel_seconds = 0.0;  // --device cuda: the kernels' own time; 0 on the model
};

Result trace(const LocalStoreAccelerator& base, const Run& run, const FrameRays& w) {
    const auto accel = base.with_local_store(run.config, run.traversal);
    std::vector<Hit> hits;
    std::vector<std::uint8_t> occluded;
    Timer timer;
    for (const FrameRays::Packet& p : w.packets) {
        hits.resize(p.primary_count);
        accel->intersect(std::span(w.primary).subspan(p.primary, p.primary_count), hits);
        occluded.resize(p.secondary_count);
        accel->occluded(std::span(w.secondary).subspan(p.secondary, p.secondary_count), occluded);
    }
    return {accel->local_store_stats(), timer.seconds()};
}

// The frame's sampled rays on the device: its primary rays, then its shadow rays, each one batch.
struct DeviceFrame {
    DeviceRayBatch primary, shadow;
    explicit DeviceFrame(const FrameRays& w)
        : primary(std::max<std::size_t>(w.primary.size(), 1)), shadow(std::max<std::size_t>(w.secondary.size(), 1)) {
        primary.upload(w.primary);
        shadow.upload(w.secondary);
    }
};

// The device's counts as the model's: a torn read went to global memory, so it is a miss; the bytes
// moved are the lines filled, by misses and by touches (a miss that found its slot being filled read
// global memory alone).
CacheStats model_counts(const DeviceCacheCounts& d, std::uint32_t line_bytes) {
    CacheStats c;
    c.hits = d.hits;
    c.misses = d.misses + d.torn;
    c.prefetches = d.prefetches;
    c.touch_hits = d.touch_hits;
    c.evictions = d.evictions;
    c.bytes = (d.misses - d.unfilled + d.prefetches) * std::uint64_t{line_bytes};
    return c;
}

// One run on the GPU, memory mode (b) with the run's layouts and access.
Result trace_device(const Scene& scene, const Run& run, const FrameRays& w, DeviceFrame& frame) {
    AccelConfig c;
    c.kind = run.structure;
    c.traversal = run.traversal;
    c.device = "cuda";
    const CacheLayout &n = run.config.node_cache, &t = run.config.triangle_cache;
    c.params = {{"memory", "shared"},
                {"access", to_string(run.config.access)},
                {"node_line", std::to_string(n.line_bytes)},
                {"node_sets", std::to_string(n.sets)},
                {"node_ways", std::to_string(n.ways)},
                {"triangle_line", std::to_string(t.line_bytes)},
                {"triangle_sets", std::to_string(t.sets)},
                {"triangle_ways", std::to_string(t.ways)}};
    const auto accel = make_device_accelerator(scene.triangles, c);
    Result r;
    Timer timer;
    if (!w.primary.empty()) r.kernel_seconds += accel->intersect_resident(frame.primary);
    if (!w.secondary.empty()) r.kernel_seconds += accel->occluded_resident(frame.shadow);
    r.wall_seconds = timer.seconds();
    const DeviceCacheStats d = accel->cache_stats();
    r.stats.node_cache = model_counts(d.node_cache, n.line_bytes);
    r.stats.triangle_cache = model_counts(d.triangle_cache, t.line_bytes);
    r.stats.rays = w.primary.size() + w.secondary.size();
    return r;
}

// Every run on the GPU, one after another; results in the order of `runs`.
std::vector<Result> trace_all_device(const Scene& scene, const std::vector<Run>& runs, const FrameRays& w) {
    DeviceFrame frame(w);
    std::vector<Result> results;
    Progress progress;
    for (const Run& run : runs) {
        if (g_cancel) throw Error("cache study cancelled");
        results.push_back(trace_device(scene, run, w, frame));
        progress(results.size(), runs.size());
    }
    return results;
}

// Runs every run on `threads` threads, each run on one thread; results in the order of `runs`.
std::vector<Result> trace_all(const std::map<std::string, std::unique_ptr<LocalStoreAccelerator>>& bases,
                              const std::vector<Run>& runs, const FrameRays& w, unsigned threads) {
    std::vector<Result> results(runs.size());
    std::atomic<std::size_t> next{0}, done{0};
    // The first failure stops every thread and is rethrown here: an exception must not leave a thread
    // (std::terminate), nor a joinable thread be destroyed when the system refuses to start the next.
    std::atomic<bool> failed{false};
    std::exception_ptr failure;
    auto fail = [&](std::exception_ptr e) {
        if (!failed.exchange(true)) failure = std::move(e);
    };
    Progress progress;
    auto work = [&] {
        for (std::size_t i = next++; i < runs.size() && !failed && !g_cancel; i = next++) {
            try {
                results[i] = trace(*bases.at(runs[i].structure), runs[i], w);
            } catch (...) {
                fail(std::current_exception());
                return;
            }
            progress(++done, runs.size());
        }
    };
    std::vector<std::thread> pool;
    try {
        for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work);
    } catch (const std::system_error& e) {
        fail(std::make_exception_ptr(Error("cannot start thread " + std::to_string(pool.size() + 1) + " of " +
                                           std::to_string(threads) + ": " + e.code().message())));
    }
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    if (g_cancel) throw Error("cache study cancelled");
    return results;
}

// trace_all over this process's share of the runs (all of them in the plain program; under MPI every
// ranks()-th), the results gathered on the leader in the order of `runs` (empty elsewhere).
std::vector<Result> trace_shared(const std::map<std::string, std::unique_ptr<LocalStoreAccelerator>>& bases,
                                 const std::vector<Run>& runs, const FrameRays& w, unsigned threads) {
    static_assert(std::is_trivially_copyable_v<Result>);
    const std::vector<std::size_t> mine = cluster::share(runs.size());
    std::vector<Run> my_runs;
    for (std::size_t i : mine) my_runs.push_back(runs[i]);
    std::vector<Result> my_results;
    cluster::together([&] { my_results = trace_all(bases, my_runs, w, threads); }, "tracing the runs");
    std::vector<std::string> bytes;
    for (const Result& r : my_results) bytes.emplace_back(reinterpret_cast<const char*>(&r), sizeof r);
    std::vector<Result> results;
    for (const std::string& b : cluster::gather_runs(runs.size(), mine, std::move(bytes)))
        std::memcpy(&results.emplace_back(), b.data(), sizeof(Result));
    return results;
}

std::string csv_header() {
    return "scene,structure,traversal,access,sweep,node_layout,node_line,node_sets,node_ways,tri_layout,tri_line,"
           "tri_sets,tri_ways,rays,node_hits,node_misses,node_hit_ratio,node_prefetches,node_bytes,node_evictions,"
           "tri_hits,tri_misses,tri_hit_ratio,tri_bytes,tri_evictions,cycles,stall_cycles,cycles_per_ray,"
           "frame_ms,wall_s\n";
}

std::string csv_row(const std::string& scene, const Run& run, const Result& r, std::uint64_t frame_rays) {
    const LocalStoreConfig& c = run.config;
    const LocalStoreStats& s = r.stats;
    const CacheStats &n = s.node_cache, &t = s.triangle_cache;
    const double frame_ms = r.kernel_seconds > 0.0
                                ? 1e3 * r.kernel_seconds / static_cast<double>(s.rays) * static_cast<double>(frame_rays)
                                : s.cycles_per_ray() * static_cast<double>(frame_rays) / (c.cost.clock_ghz * 1e6);
    // A cache the sampled rays never read has no hit ratio: an empty field, where 0 read as the worst.
    auto ratio = [](const CacheStats& c) {
        char text[32] = "";
        if (c.hits + c.misses > 0) std::snprintf(text, sizeof text, "%.6f", c.hit_ratio());
        return std::string(text);
    };
    char buf[1024];  // the fields after the scene's name, which is the user's and of any length
    std::snprintf(buf, sizeof buf,
                  "%s,%s,%s,%s,%s,%u,%u,%u,%s,%u,%u,%u,%llu,%llu,%llu,%s,%llu,%llu,%llu,%llu,%llu,%s,%llu,%llu,"
                  "%llu,%llu,%.3f,%.4f,%.4f\n",
                  run.structure.c_str(), run.traversal.c_str(), to_string(c.access), run.sweep.c_str(),
                  c.node_cache.to_string().c_str(), c.node_cache.line_bytes, c.node_cache.sets, c.node_cache.ways,
                  c.triangle_cache.to_string().c_str(), c.triangle_cache.line_bytes, c.triangle_cache.sets,
                  c.triangle_cache.ways, static_cast<unsigned long long>(s.rays),
                  static_cast<unsigned long long>(n.hits), static_cast<unsigned long long>(n.misses), ratio(n).c_str(),
                  static_cast<unsigned long long>(n.prefetches), static_cast<unsigned long long>(n.bytes),
                  static_cast<unsigned long long>(n.evictions), static_cast<unsigned long long>(t.hits),
                  static_cast<unsigned long long>(t.misses), ratio(t).c_str(), static_cast<unsigned long long>(t.bytes),
                  static_cast<unsigned long long>(t.evictions), static_cast<unsigned long long>(s.cycles),
                  static_cast<unsigned long long>(s.stall_cycles), s.cycles_per_ray(), frame_ms, r.wall_seconds);
    return detail::csv_field(scene) + ',' + buf;
}

// One line of best_layouts.md: the fastest layout of a sweep, the fastest direct-mapped one and the
// study's, each with its hit ratio and modelled cycles per ray.
std::string best_layout_line(const std::string& scene, const std::vector<Run>& runs, const std::vector<Result>& results,
                             const std::vector<std::size_t>& group) {
    const Run& first = runs[group.front()];
    const bool node = first.sweep == "node";
    auto layout = [&](std::size_t i) { return node ? runs[i].config.node_cache : runs[i].config.triangle_cache; };
    // What a layout costs: the model's cycles, or on the device the kernels' time.
    auto cost = [&](std::size_t i) {
        return results[i].kernel_seconds > 0.0 ? results[i].kernel_seconds : static_cast<double>(results[i].stats.cycles);
    };
    auto per_ray = [&](std::size_t i) {
        const Result& r = results[i];
        return r.kernel_seconds > 0.0 ? 1e9 * r.kernel_seconds / static_cast<double>(r.stats.rays) : r.stats.cycles_per_ray();
    };
    const CacheLayout study = node ? study_node_layout(first.structure) : kStudyTriangleLayout;
    std::size_t best = group.front(), best_direct = group.front(), at_study = group.front();
    for (std::size_t i : group) {
        if (cost(i) < cost(best)) best = i;
        if (layout(i).ways == 1 && (layout(best_direct).ways != 1 || cost(i) < cost(best_direct))) best_direct = i;
        if (layout(i) == study) at_study = i;
    }
    auto cell = [&](std::size_t i) {
        const CacheStats& c = node ? results[i].stats.node_cache : results[i].stats.triangle_cache;
        char buf[96];
        // A sample whose rays never read the swept cache (a corner packet of empty space) has no
        // hit ratio: 0 % would read as the worst.
        if (c.hits + c.misses == 0)
            std::snprintf(buf, sizeof buf, "%s: no reads", layout(i).to_string().c_str());
        else
            std::snprintf(buf, sizeof buf, results[i].kernel_seconds > 0.0 ? "%s: %.1f %%, %.2f" : "%s: %.1f %%, %.0f",
                          layout(i).to_string().c_str(), 100.0 * c.hit_ratio(), per_ray(i));
        return std::string(buf);
    };
    char buf[512];
    std::snprintf(buf, sizeof buf, " | %s | %s | %s | %s | %s | %s | %s | %.2f |\n", first.structure.c_str(), first.traversal.c_str(), to_string(first.config.access),
                  node ? "nodes" : "triangles", cell(best).c_str(), cell(best_direct).c_str(), cell(at_study).c_str(),
                  cost(at_study) / cost(best));
    return "| " + detail::markdown_cell(scene) + buf;
}

std::vector<std::string> checked_choices(const std::string& option, const std::vector<std::string>& values,
                                         const std::vector<std::string>& allowed) {
    if (values.empty()) throw Error(option + " needs at least one value");
    cluster::check_no_repeats(option, values);
    for (const std::string& v : values)
        if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
            std::string list;
            for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
            throw Error(option + " '" + v + "' is not one of: " + list);
        }
    return values;
}

}  // namespace

Runner add_cache_study(CLI::App& app) {
    struct Options {
        std::vector<std::string> scenes;
        std::string out = "cache-study", size, device = "cpu";
        int packet = RenderOptions{}.packet, sample = 8;
        unsigned threads = 0;
        bool overwrite = false;
        std::vector<std::string> structures{"kd", "bih"}, traversals{"branched", "branchless"},
            access{"sync", "async"}, sweeps{"node", "triangle"};
    };
    auto o = std::make_shared<Options>();
    auto* cmd = app.add_subcommand("cache-study", "The study's cache experiments (Graphs 5-1 to 5-10) through the "
                                                  "local-store model, or the GPU's shared-memory caches: CSV for "
                                                  "bench/plot_cache_study.py");
    cmd->add_option("scenes", o->scenes, scene_help() + "; one or more")->required();
    cmd->add_option("-o,--out", o->out, "Output folder (cache_study.csv, best_layouts.md)")
        ->capture_default_str()
        ->check(non_empty());
    cmd->add_option("--size", o->size, "Frame size WIDTHxHEIGHT (default: each view file's)")->check(non_empty());
    cmd->add_option("--packet", o->packet, "Packet edge P: P x P primary rays, then their shadow rays")
        ->capture_default_str();
    cmd->add_option("--sample", o->sample, "Trace the packets whose column + row is a multiple of N (1: all)")
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "Runs traced at once (0: all cores)")->capture_default_str();
    cmd->add_option("--structures", o->structures, "Structures: kd, bih")->capture_default_str();
    cmd->add_option("--traversals", o->traversals, "Traversals: branched, branchless")->capture_default_str();
    cmd->add_option("--access", o->access, "Cache access modes: sync, async")->capture_default_str();
    cmd->add_option("--device", o->device,
                    "cpu: the local-store model (modelled cycles); cuda: the GPU's software caches in shared "
                    "memory (memory mode (b), measured kernel time)")
        ->capture_default_str();
    cmd->add_option("--sweeps", o->sweeps, "Caches swept: node (Graphs 5-1..5-6), triangle (5-7..5-10)")
        ->capture_default_str();
    cmd->add_flag("--overwrite", o->overwrite, "Replace existing output files");
    cluster::add_sweep_options(*cmd);
    return [o] {
        // Under MPI each step runs on every rank, a step that fails on one fails on all, and the runs
        // are shared among the ranks (cluster.hpp); rank 0 alone prints and writes.
        cluster::same_command_line("cache-study");
        std::string csv_path, md_path;
        cluster::together([&] {
            checked_choices("--structures", o->structures, {"kd", "bih"});
            checked_choices("--traversals", o->traversals, {"branched", "branchless"});
            checked_choices("--access", o->access, {"sync", "async"});
            checked_choices("--device", {o->device}, {"cpu", "cuda"});
            if (o->device == "cuda") {
                if (cluster::ranks() > 1)
                    throw Error("--device cuda runs in one process (one GPU); run it without mpirun");
                const DeviceInfo gpu = cuda_device_info();
                if (!gpu.present) throw Error("--device cuda: no device (" + gpu.reason + ")");
            }
            checked_choices("--sweeps", o->sweeps, {"node", "triangle"});
            if (o->sample < 1 || o->sample > 1024)
                throw Error("--sample " + std::to_string(o->sample) + " must lie in [1, 1024]");
            if (o->packet < 1 || o->packet > kMaxPacket)
                throw Error("--packet " + std::to_string(o->packet) + " must lie in [1, " +
                            std::to_string(kMaxPacket) + "]");
            if (o->device == "cpu") check_packet_fits(o->packet, LocalStoreConfig{}.budget_bytes, "");
            cluster::check_no_repeats("scenes", o->scenes);
            check_threads(o->threads);
            csv_path = (std::filesystem::path(o->out) / "cache_study.csv").string();
            md_path = (std::filesystem::path(o->out) / "best_layouts.md").string();
            if (cluster::leader()) {
                check_output_folder("--out", o->out);
                std::error_code ec;
                if (std::filesystem::is_directory(o->out, ec))
                    for (const std::string& p : {csv_path, md_path}) check_output_file(p, o->overwrite);
                check_distinct_files({{"--out", csv_path}, {"--out", md_path}}, scene_files(o->scenes));
            }
        }, "checking the options");
        const unsigned threads = o->threads ? o->threads : cluster::cores();

        std::string csv = csv_header();
        const bool gpu = o->device == "cuda";
        std::string md = std::string("| scene | structure | traversal | access | cache | best layout: hit ratio, ") +
                         (gpu ? "kernel ns/ray" : "cycles/ray") +
                         " | best direct-mapped | the study's layout | study / best |\n|---|---|---|---|---|---|---|---|---|\n";
        Timer total;
        std::map<std::string, std::string> named;  // scene name -> the spec that gave it
        for (const std::string& spec : o->scenes) {
            const Scene scene = cluster::load_scene(spec);
            // The results name their rows by the scene: two scenes of one name would be one in the
            // CSV, the table and the graphs.
            // Agreed, so said once: every rank found it and printed it (found by audit, 2026-12-07).
            cluster::together([&] {
                if (const auto [at, fresh] = named.emplace(scene.name, spec); !fresh)
                    throw Error(spec + " and " + at->second + " are both the scene '" + scene.name +
                                "', and the results name their rows by scene: give one view file another \"name\"");
            }, "naming the scenes");
            int width = scene.width, height = scene.height;
            FrameRays w;
            std::map<std::string, std::unique_ptr<LocalStoreAccelerator>> bases;
            std::vector<Run> runs;
            cluster::together([&] {
                if (!o->size.empty()) std::tie(width, height) = parse_image_size("--size", o->size);
                for (const std::string& structure : o->structures) {
                    AccelConfig ac;
                    ac.kind = structure;
                    ac.threads = o->threads;
                    if (!gpu) bases[structure] = make_local_store_accelerator(scene.triangles, ac, LocalStoreConfig{});
                    for (const std::string& sweep : o->sweeps)
                        for (const std::string& traversal : o->traversals)
                            for (const std::string& access : o->access)
                                for (const CacheLayout& layout : swept_layouts()) {
                                    Run run{structure, traversal, sweep, LocalStoreConfig{}};
                                    run.config.access = parse_cache_access("--access", access);
                                    run.config.batch_rays = static_cast<std::size_t>(o->packet) * o->packet;
                                    run.config.node_cache = sweep == "node" ? layout : study_node_layout(structure);
                                    run.config.triangle_cache = sweep == "node" ? kFixedTriangleLayout : layout;
                                    runs.push_back(run);
                                }
                }
                // Every run's local store made once before the frame is traced, as the run will make
                // it: a --packet whose batch leaves no room for the largest swept cache fails here, not
                // after the tracing.
                if (!gpu)
                    for (const Run& run : runs) {
                        try {
                            bases.at(run.structure)->with_local_store(run.config, run.traversal);
                        } catch (const Error& e) {
                            throw Error("--packet " + std::to_string(o->packet) + ": " + e.what());
                        }
                    }
                w = sampled_frame(scene, width, height, o->packet, o->sample);
                if (cluster::leader())
                    std::printf("%s: %zu triangles, %dx%d; %zu of %zu packets of %dx%d (column + row a multiple of %d): "
                                "%zu primary + %zu shadow rays of the frame's %llu\n",
                                scene.name.c_str(), scene.triangles.size(), width, height, w.packets.size(),
                                PacketGrid(width, height, o->packet).count(), o->packet, o->packet, o->sample,
                                w.primary.size(), w.secondary.size(), static_cast<unsigned long long>(w.frame_ray_count));
                std::fflush(stdout);
            }, "building the structures");
            Timer timer;
            const std::vector<Result> results = [&] {
                const Cancellable cancellable;
                std::vector<Result> r = gpu ? trace_all_device(scene, runs, w) : trace_shared(bases, runs, w, threads);
                // During the last run or the gather, on any rank: agreed, so that every rank ends here
                // (one rank alone throwing left the others in the next scene's collectives: MPI_ERR_TRUNCATE,
                // or results written beside a "cancelled"; found by audit, 2026-12-07).
                cluster::together([] { if (g_cancel) throw Error("cache study cancelled"); }, "finishing the runs");
                return r;
            }();
            if (!cluster::leader()) continue;
            if (gpu)
                std::printf("  %zu runs in %.1f s on %s\n", runs.size(), timer.seconds(), cuda_device_info().name.c_str());
            else if (cluster::ranks() == 1)
                std::printf("  %zu runs in %.1f s on %u threads\n", runs.size(), timer.seconds(), threads);
            else
                std::printf("  %zu runs in %.1f s on %d ranks of %u threads\n", runs.size(), timer.seconds(),
                            cluster::ranks(), threads);
            std::fflush(stdout);
            std::map<std::string, std::vector<std::size_t>> groups;  // runs of one sweep, in order
            std::vector<std::string> group_order;
            for (std::size_t i = 0; i < runs.size(); ++i) {
                csv += csv_row(scene.name, runs[i], results[i], w.frame_ray_count);
                const std::string key = runs[i].structure + runs[i].sweep + runs[i].traversal +
                                        to_string(runs[i].config.access);
                if (groups[key].empty()) group_order.push_back(key);
                groups[key].push_back(i);
            }
            for (const std::string& key : group_order) md += best_layout_line(scene.name, runs, results, groups[key]);
        }
        if (!cluster::leader()) return 0;
        const Cancellable cancellable;  // a signal while the results are written is seen after (run): both whole
        std::error_code ec;
        std::filesystem::create_directories(o->out, ec);
        if (!std::filesystem::is_directory(o->out, ec)) throw Error("--out '" + o->out + "': cannot create the folder");
        write_file_atomically(csv_path, csv, o->overwrite);
        write_file_atomically(md_path, md, o->overwrite);
        std::printf("\n%s\nwrote %s and %s in %.1f s; draw the graphs with:\n"
                    "  python3 bench/plot_cache_study.py %s %s\n",
                    md.c_str(), csv_path.c_str(), md_path.c_str(), total.seconds(), csv_path.c_str(), o->out.c_str());
        return 0;
    };
}

}  // namespace cellrt::cli
