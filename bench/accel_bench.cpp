// Structures against Embree, in the same run on the same rays: build time, memory and rays per second
// of primary rays and of a second kind of rays for every structure and traversal, per scene.
//
// The rays of a scene (--rays) are those of one frame at the view's size: one primary ray per pixel, in
// 16 x 16 packets in the order the renderer traces them, and the rays the renderer casts from their
// hits (workload.hpp): `frame`, one shadow ray toward the light per hit; `ao`, --ao-samples AO rays per
// hit (any hit); `diffuse`, one cosine-weighted bounce per hit (closest hit). The hits are found by an
// exact structure, so every configuration traces the very same rays. `random` rays are incoherent:
// origins in the scene's box, directions uniform. The second kind is reported in the shadow_* fields.
// Each configuration is built `--builds` times, the configurations in turn (median reported, with the
// build's peak memory and the tree's SAH cost); then, after a warm-up pass each,
// the configurations are traced in turn, `--repeats` rounds (median per ray kind), single-threaded
// unless `--threads` says otherwise.
//
// The unit of work is a scene: its rays, every configuration (Embree's with them) built and timed in
// turn. cellrt_bench-mpi gives each rank whole scenes and gathers their tables and rows on rank 0, which
// prints and writes them in the one-process order (bench_cluster.hpp, docs/DISTRIBUTED.md).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include <nlohmann/json.hpp>

// Under callgrind (bench/step_costs.py runs it with --instr-atstart=no) only the traced passes are
// instrumented: loading, building and the counting passes run at valgrind's uninstrumented speed.
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#endif

#include "bench_cluster.hpp"
#include "bench_common.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/error.hpp"
#include "cellrt/image.hpp"
#include "cellrt/sampling.hpp"
#include "cellrt/scene.hpp"
#include "core/timer.hpp"
#include "kernel/subtree.hpp"
#include "cellrt/workload.hpp"

namespace {

using namespace cellrt;
using bench::median;
namespace cluster = cli::cluster;

// The rays every configuration traces: primary rays (closest hit), and rays of a second kind, any hit
// or closest hit as the kind asks.
struct Rays {
    std::vector<Ray> primary, secondary;
    RayKind secondary_kind = RayKind::shadow;
};

// The frame workload in 16 x 16 packets, the hits found by `exact` (workload.hpp).
Rays frame(const Scene& scene, const Accelerator& exact, int width, int height, const ShadingOptions& shading) {
    FrameRays f = frame_rays(scene, width, height, 16, exact, shading);
    return {std::move(f.primary), std::move(f.secondary), f.secondary_kind};
}

// Incoherent rays, for the packet kernels' worst case: origins uniform in the scene's box,
// directions uniform on the sphere; the same rays (with tfar a third of the box's diagonal) serve as
// "shadow" rays. Deterministic (SplitMix64).
Rays random_rays(const Scene& scene, std::size_t n) {
    const Box3 b = scene.bounds();
    std::uint64_t state = 0x9e3779b97f4a7c15ull;
    auto next = [&] { return unit_float(mix64(state += 0x9e3779b97f4a7c15ull)); };
    Rays f;
    while (f.primary.size() < n) {
        Ray r;
        for (int a = 0; a < 3; ++a) r.org[a] = b.lo[a] + (b.hi[a] - b.lo[a]) * next();
        const Vec3 d{2.f * next() - 1.f, 2.f * next() - 1.f, 2.f * next() - 1.f};
        if (dot(d, d) > 1.f || dot(d, d) < 1e-6f) continue;
        r.dir = normalize(d);
        f.primary.push_back(r);
        r.tfar = length(b.extent()) / 3.f;
        f.secondary.push_back(r);
    }
    return f;
}

struct Options {
    std::string scenes_dir = "../shared/scenes";
    std::vector<std::string> scenes{"sponza", "sibenik", "bunny", "teapot", "builtin:city", "builtin:forest"};
    std::vector<std::string> configs{"embree:single", "embree:packet16", "kd:rec", "kd:branched", "kd:branchless",
                                     "kd+auto", "bih:branched", "bih:branchless", "bih+auto", "bih+auto@split=sah", "bvh", "auto"};
    int repeats = 5, builds = 3, batch = 256, ao_samples = ShadingOptions{}.ao_samples;
    unsigned threads = 1;
    std::string size, json_path, clock = "wall", ray_kind = "frame";
    bool overwrite = false;
    bool scenes_named = false;  // --scenes given: a scene not found is an error, not skipped
};

// Reads the command line into `o`; returns the exit status where the program ends there (--help, a bad
// option), as CLI11_PARSE would. A bad configuration or size fails on every process (cluster.hpp).
std::optional<int> parse_options(int argc, char** argv, Options& o) {
    CLI::App app{"cellrt structures vs Embree: build time, memory, Mrays/s on the same rays in the same run"};
    app.add_option("--scenes-dir", o.scenes_dir, "Folder of the shared scenes")->capture_default_str();
    app.add_option("--scenes", o.scenes, "Shared scene names or builtin:... specs")->capture_default_str();
    app.add_option("--configs", o.configs, "KIND[:TRAVERSAL][+SIMD][@NAME=VALUE,...]; embree ones are the yardsticks")->capture_default_str();
    app.add_option("--repeats", o.repeats, "Timed passes per ray kind (median)")->capture_default_str()->check(CLI::Range(1, 1000));
    app.add_option("--builds", o.builds, "Timed builds (median)")->capture_default_str()->check(CLI::Range(1, 100));
    app.add_option("--batch", o.batch, "Rays per accelerator call")->capture_default_str()->check(CLI::Range(1, 1 << 20));
    app.add_option("--threads", o.threads, "Build threads (tracing is single-threaded)")->capture_default_str();
    app.add_option("--size", o.size, "Image size WxH (default: the view file's)");
    app.add_option("--json", o.json_path, "Write every result as JSON")->check(bench::non_empty_path());
    app.add_flag("--overwrite", o.overwrite, "Replace an existing --json file");
    app.add_option("--rays", o.ray_kind,
                   "frame: a frame's primary and shadow rays; ao: its primary and AO rays; diffuse: its primary "
                   "rays and one bounce per hit; random: incoherent rays")
        ->capture_default_str()
        ->check(CLI::IsMember({"frame", "ao", "diffuse", "random"}));
    app.add_option("--ao-samples", o.ao_samples, "AO rays per primary hit (--rays ao)")
        ->capture_default_str()
        ->check(CLI::Range(1, kMaxAoSamples));
    app.add_option("--clock", o.clock,
                   "Time by the wall clock, or by CPU time: this thread's for tracing, the process's (all threads) "
                   "for builds")
        ->capture_default_str()
        ->check(CLI::IsMember({"wall", "cpu"}));
    cluster::add_bench_options(app);
    cluster::strict_numbers(app);
    if (const int status = cluster::parse(app, argc, argv); status >= 0) return status;
    cluster::same_command_line("a sweep", {"--scenes-dir"});
    o.scenes_named = app.count("--scenes") > 0;
    cluster::together([&] {
        bench::check_configs(o.configs);
        cluster::check_no_repeats("--configs", o.configs);
        cluster::check_no_repeats("--scenes", o.scenes);
        if (!o.size.empty()) parse_image_size("--size", o.size);
        if (o.threads > kMaxWorkers)
            throw Error("--threads " + std::to_string(o.threads) + " must lie in [0, " + std::to_string(kMaxWorkers) + "]");
        // As cellrt_scaling says it: the samples of rays that are not traced (found by audit, 2026-12-07).
        if (app.count("--ao-samples") > 0 && o.ray_kind != "ao") throw Error("--ao-samples needs --rays ao");
    }, "checking the options");
    return std::nullopt;
}

// What an accelerator answers for a set of rays: their closest hits, or whether each is occluded.
struct Answers {
    std::vector<Hit> hits;
    std::vector<std::uint8_t> occluded;
};

// Answers `rays` as their kind asks (closest hit or any hit) in batches of `batch` rays, one
// accelerator call each, adding the work to `counters` where given.
void answer(const Accelerator& accel, std::span<const Ray> rays, RayKind kind, std::size_t batch, Answers& out,
            TraversalCounters* counters = nullptr) {
    const bool closest = closest_hit(kind);
    if (closest) out.hits.resize(rays.size());
    else out.occluded.resize(rays.size());
    for (std::size_t i = 0; i < rays.size(); i += batch) {
        const std::size_t n = std::min(batch, rays.size() - i);
        if (closest) accel.intersect(rays.subspan(i, n), std::span(out.hits).subspan(i, n), counters);
        else accel.occluded(rays.subspan(i, n), std::span(out.occluded).subspan(i, n), counters);
    }
}

// The answers in `a` and `b` that differ: the triangle hit, or occluded or not.
std::size_t differing(const Answers& a, const Answers& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.hits.size(); ++i) n += a.hits[i].prim != b.hits[i].prim;
    for (std::size_t i = 0; i < a.occluded.size(); ++i) n += a.occluded[i] != b.occluded[i];
    return n;
}

// A scene's rays of `kind` and a kd-tree's exact answers for both sets, from a kd-tree that is gone
// before the configurations are built.
struct SceneRays {
    Rays rays;
    Answers primary, secondary;
};

SceneRays scene_rays(const Scene& scene, const Options& o, int width, int height) {
    const auto kd = make_accelerator(scene.triangles, AccelConfig{"kd"});
    SceneRays s;
    if (o.ray_kind == "random") {
        s.rays = random_rays(scene, static_cast<std::size_t>(width) * height);
    } else {
        ShadingOptions shading;
        shading.shading = o.ray_kind == "frame" ? Shading::direct : parse_shading(o.ray_kind);
        shading.ao_samples = o.ao_samples;
        s.rays = frame(scene, *kd, width, height, shading);
    }
    answer(*kd, s.rays.primary, RayKind::primary, s.rays.primary.size(), s.primary);
    answer(*kd, s.rays.secondary, s.rays.secondary_kind, s.rays.secondary.size(), s.secondary);
    return s;
}

struct Result {
    std::string config;
    bool embree = false;
    double build_s = 0, memory_mib = 0, primary_s = 0, shadow_s = 0;
    double build_peak_mib = 0;  // the build's peak resident memory above what the process held before it
    double sah_cost = 0;        // the tree's report; 0 where the structure has none
    std::string routed;         // `auto`: the share of rays each path answered, per query (its "routed" setting)
    std::size_t differing = 0, differing_secondary = 0;  // answers that differ from the exact ones
    TraversalCounters primary_work, shadow_work;
    bool counts_work = true;    // whether the work counters hold nodes, leaves and triangles (not Embree's)
};

// A configuration: its structure, its figures so far and its timed passes.
struct Entry {
    Result r;
    std::unique_ptr<Accelerator> accel;
    std::vector<double> primary_s, shadow_s;
};

// Every configuration built --builds times, in turn (A B C, A B C, ...: a slow spell of a shared machine
// falls on all of them alike), median build time and peak memory; one that this binary or processor
// cannot build is skipped with a message.
std::vector<Entry> build_configurations(const Scene& scene, const Options& o) {
    struct Pending {
        Entry e;
        AccelConfig cfg;
        std::vector<double> times, peaks;
    };
    std::vector<Pending> pending;
    for (const std::string& text : o.configs) {
        AccelConfig cfg = parse_accel_config(text);
        cfg.threads = o.threads;
        if (!bench::built_in(cfg.kind)) continue;
        Pending p;
        p.e.r.config = text;
        p.e.r.embree = cfg.kind == "embree";
        p.cfg = cfg;
        pending.push_back(std::move(p));
    }
    for (int b = 0; b < o.builds; ++b)
        for (auto it = pending.begin(); it != pending.end();) {
            Pending& p = *it;
            try {
                p.e.accel.reset();
                bench::reset_peak_memory();
                const double before = bench::resident_memory_bytes();
                p.e.accel = make_accelerator(scene.triangles, p.cfg);
                p.peaks.push_back(std::max(0.0, bench::peak_memory_bytes() - before));
                const AccelStats st = p.e.accel->stats();
                p.times.push_back(o.clock == "cpu" ? st.build_cpu_seconds : st.build_seconds);
                ++it;
            } catch (const Error& err) {  // a packet width this processor lacks; anything else is an error
                if (bench::simd_runs_here(p.cfg)) throw Error(p.e.r.config + " on " + scene.name + ": " + err.what());
                std::fprintf(stderr, "skipping %s: %s\n", p.e.r.config.c_str(), err.what());
                it = pending.erase(it);
            }
        }
    std::vector<Entry> entries;
    for (Pending& p : pending) {
        Entry& e = p.e;
        e.r.build_s = median(p.times);
        e.r.build_peak_mib = median(p.peaks) / (1024.0 * 1024.0);
        const AccelStats st = e.accel->stats();
        e.r.memory_mib = static_cast<double>(st.memory_bytes) / (1024.0 * 1024.0);
        if (st.tree) e.r.sah_cost = st.tree->sah_cost;
        entries.push_back(std::move(e));
    }
    return entries;
}

double per_ray(std::uint64_t n, const TraversalCounters& c) { return c.rays ? double(n) / double(c.rays) : 0.0; }

// A pass's nodes, leaves and triangles per ray; "–" and null where the configuration counts none
// (Embree, AccelStats::counts_work) or traced no ray: a zero there read as a measured zero (found by
// audit, 2026-12-07).
std::string work_text(const TraversalCounters& c, bool counted) {
    if (!counted || !c.rays) return "–";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f / %.1f / %.1f", per_ray(c.nodes, c), per_ray(c.leaves, c), per_ray(c.triangles, c));
    return buf;
}

nlohmann::json work_json(const TraversalCounters& c, bool counted) {
    if (!counted || !c.rays) return nullptr;
    return {{"nodes", per_ray(c.nodes, c)}, {"leaves", per_ray(c.leaves, c)}, {"triangles", per_ray(c.triangles, c)}};
}

// Seconds on the wall clock, or on this thread's CPU clock (--clock cpu: time the thread was not
// running is left out, which steadies figures on a busy machine; wall time is what users see).
double now(bool cpu_clock) {
    timespec ts;
    clock_gettime(cpu_clock ? CLOCK_THREAD_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// After a warm-up pass each, the timed passes go round the configurations (primary and shadow rays
// of each in turn, --repeats rounds), so that a slow spell of a shared machine falls on all of them
// alike and the ratios hold.
void timed_passes(std::vector<Entry>& entries, const Rays& rays, const Options& o) {
    Answers primary, secondary;
    const std::size_t bs = static_cast<std::size_t>(o.batch);
    const bool cpu = o.clock == "cpu";
    auto timed = [&](const Accelerator& accel, std::span<const Ray> r, RayKind kind, Answers& out) {
        const double start = now(cpu);
        answer(accel, r, kind, bs, out);
        return now(cpu) - start;
    };
    auto passes = [&](Entry& e) {
        const double tp = timed(*e.accel, rays.primary, RayKind::primary, primary);
        const double ts = timed(*e.accel, rays.secondary, rays.secondary_kind, secondary);
        return std::pair{tp, ts};
    };
    for (Entry& e : entries) passes(e);  // warm-up
    for (int k = 0; k < o.repeats; ++k)
        for (Entry& e : entries) {
            const auto [tp, ts] = passes(e);
            e.primary_s.push_back(tp);
            e.shadow_s.push_back(ts);
        }
}

// Each configuration's median times, its work per ray and how many of its answers differ from the
// exact ones; the structures are freed on the way.
std::vector<Result> results_of(std::vector<Entry>& entries, const SceneRays& s) {
    std::vector<Result> results;
    for (Entry& e : entries) {
        Result& r = e.r;
        r.primary_s = median(e.primary_s);
        r.shadow_s = median(e.shadow_s);
        const AccelStats st = e.accel->stats();
        r.routed = st.setting("routed").value_or("");  // the warm-up and timed passes
        r.counts_work = st.counts_work;
        Answers primary, secondary;
        answer(*e.accel, s.rays.primary, RayKind::primary, s.rays.primary.size(), primary, &r.primary_work);
        answer(*e.accel, s.rays.secondary, s.rays.secondary_kind, s.rays.secondary.size(), secondary, &r.shadow_work);
        r.differing = differing(primary, s.primary);
        r.differing_secondary = differing(secondary, s.secondary);
        results.push_back(r);
        e.accel.reset();
    }
    return results;
}

// The scene's table, with ratios to Embree in this run: builds to its first configuration (its
// default build), rays per second to rtcIntersect1 (`embree:single`) and to its fastest configuration.
void print_table(std::FILE* out, const std::vector<Result>& results, const Rays& rays) {
    const double np = static_cast<double>(rays.primary.size()), ns = static_cast<double>(rays.secondary.size());
    auto total = [&](const Result& r) { return (np + ns) / (r.primary_s + r.shadow_s) * 1e-6; };
    const Result *first = nullptr, *single = nullptr, *best = nullptr;
    for (const Result& r : results) {
        if (!r.embree) continue;
        if (!first) first = &r;
        // `embree` alone is rtcIntersect1 too; with both named, the first is the yardstick.
        if (!single && (r.config == "embree:single" || r.config == "embree")) single = &r;
        if (!best || total(r) > total(*best)) best = &r;
    }
    const char* second = to_string(rays.secondary_kind);
    std::fprintf(out, "| config | build ms | build ÷ Embree | build peak MiB | memory MiB | SAH cost | primary Mrays/s | "
                "%s Mrays/s | total Mrays/s | × Embree 1 | × Embree best | answers ≠ exact | nodes/leaves/tris per "
                "primary ray | per %s ray |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
                 second, second);
    auto ratio = [](const Result* y, double value, double of_y) {
        if (!y) return std::string("–");
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.2f", value / of_y);
        return std::string(buf);
    };
    for (const Result& r : results) {
        const TraversalCounters &pw = r.primary_work, &sw = r.shadow_work;
        char sah[32] = "–";
        if (r.sah_cost > 0) std::snprintf(sah, sizeof sah, "%.2f", r.sah_cost);
        std::fprintf(out,
                     "| %s | %.1f | %s | %.1f | %.2f | %s | %.2f | %.2f | %.2f | %s | %s | %zu | %s | %s |\n",
                     r.config.c_str(), r.build_s * 1e3, ratio(first, r.build_s, first ? first->build_s : 1).c_str(),
                     r.build_peak_mib, r.memory_mib, sah, np / r.primary_s * 1e-6, ns / r.shadow_s * 1e-6, total(r),
                     ratio(single, total(r), single ? total(*single) : 1).c_str(),
                     ratio(best, total(r), best ? total(*best) : 1).c_str(), r.differing + r.differing_secondary,
                     work_text(pw, r.counts_work).c_str(), work_text(sw, r.counts_work).c_str());
    }
}

nlohmann::json json_row(const Scene& scene, int width, int height, const Options& o, const Rays& rays,
                        const Result& r) {
    const TraversalCounters &pw = r.primary_work, &sw = r.shadow_work;
    nlohmann::json row = {{"scene", scene.name},
            {"config", r.config},
            {"rays", o.ray_kind},
            {"shadow_kind", to_string(rays.secondary_kind)},
            {"ao_samples", o.ray_kind == "ao" ? o.ao_samples : 0},
            {"width", width}, {"height", height}, {"triangles", scene.triangles.size()},
            {"build_seconds", r.build_s}, {"clock", o.clock}, {"build_threads", detail::build_concurrency(o.threads)},
            {"build_peak_mib", r.build_peak_mib}, {"memory_mib", r.memory_mib}, {"sah_cost", r.sah_cost},
            // The second kind of rays (shadow, AO, bounce or random) keeps the shadow_* names.
            {"primary_rays", rays.primary.size()}, {"shadow_rays", rays.secondary.size()},
            {"primary_seconds", r.primary_s}, {"shadow_seconds", r.shadow_s},
            {"differing_primary_hits", r.differing}, {"differing_shadow_answers", r.differing_secondary},
            {"primary_per_ray", work_json(pw, r.counts_work)}, {"shadow_per_ray", work_json(sw, r.counts_work)}};
    if (!r.routed.empty()) row["routed"] = r.routed;
    return row;
}

// One scene: its rays, every configuration built and timed; its table (Markdown) and its JSON rows, as
// {"table": ..., "rows": [...]}.
nlohmann::json bench_scene(const Scene& scene, const Options& o) {
    const auto [w, h] = o.size.empty() ? std::pair{scene.width, scene.height} : parse_image_size("--size", o.size);
    const SceneRays s = scene_rays(scene, o, w, h);
    std::vector<Entry> entries = build_configurations(scene, o);
    CALLGRIND_START_INSTRUMENTATION;
    timed_passes(entries, s.rays, o);
    CALLGRIND_STOP_INSTRUMENTATION;
    const std::vector<Result> results = results_of(entries, s);
    std::fprintf(stderr, "%s done\n", scene.name.c_str());
    char* text = nullptr;
    std::size_t length = 0;
    std::FILE* table = open_memstream(&text, &length);
    if (!table) throw Error("cannot make the table: out of memory");
    std::fprintf(table, "\n### %s: %zu triangles, %dx%d, %s rays: %zu primary + %zu %s\n\n", scene.name.c_str(),
                 scene.triangles.size(), w, h, o.ray_kind.c_str(), s.rays.primary.size(), s.rays.secondary.size(),
                 to_string(s.rays.secondary_kind));
    print_table(table, results, s.rays);
    std::fclose(table);
    nlohmann::json out{{"table", std::string(text, length)}, {"rows", nlohmann::json::array()}};
    std::free(text);
    for (const Result& r : results) out["rows"].push_back(json_row(scene, w, h, o, s.rays, r));
    return out;
}

int run(int argc, char** argv) {
    Options o;
    if (const std::optional<int> status = parse_options(argc, argv, o)) return *status;
    std::vector<std::string> named;
    for (const std::string& name : o.scenes) named.push_back(bench::scene_file(o.scenes_dir, name));
    bench::check_results_paths({{"--json", o.json_path}}, o.overwrite, named);
    const std::vector<std::string> specs = bench::found_scenes(o.scenes_dir, o.scenes, o.scenes_named);
    nlohmann::json out = nlohmann::json::array();
    // A scene a run: its configurations, Embree's among them, stay together on one process.
    cluster::sweep(
        specs.size(), [&](std::size_t i) { return bench_scene(load_scene(specs[i]), o).dump(); },
        [&](std::size_t, const std::string& result) {
            const nlohmann::json scene = nlohmann::json::parse(result);
            std::fputs(scene["table"].get<std::string>().c_str(), stdout);
            std::fflush(stdout);
            for (const nlohmann::json& row : scene["rows"]) out.push_back(row);
        },
        "benchmarking the scenes");
    if (!o.json_path.empty()) bench::write_results(o.json_path, out.dump(1) + "\n", o.overwrite);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return cellrt::bench::main_on_cluster(argc, argv, "cellrt_bench", run); }
