// The study's scaling measurement (its Tables 5-1 and 5-2), with Embree alongside: seconds per frame
// (512 x 512, primary rays and those their --shading casts, by default the study's one shadow ray per
// hit) for 1..N workers, per scene, structure, dispatch mode and packet size. Every point is a warm-up
// frame and the median of --repeats frames, each timed frame the second of two drawn back to back, the
// structures and worker counts interleaved round by round (the efficiency and the packet time ratio are medians of
// each round's own ratios); every table shows cellrt's time and its rays per second as a ratio to
// Embree's with the same workers, dispatch and packet size, measured in the same run. Where the
// efficiency goes is split: the share of the workers' time spent tracing and what the schedule took of
// the rest (waking the workers, between packets, waiting for the last one at the end), and how much
// longer the same packets took with N workers than with one (shared caches and memory, the clock).
// Writes Markdown tables to stdout and every point as JSON and CSV; bench/plot_scaling.py draws the
// curves.
//
// The unit of work is a scene: every structure (Embree's with them) built and measured for every
// dispatch mode and packet size. cellrt_scaling-mpi gives each rank whole scenes and gathers their
// points on rank 0, which prints and writes them in the one-process order (bench_cluster.hpp,
// docs/DISTRIBUTED.md).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_cluster.hpp"
#include "bench_common.hpp"
#include "core/csv.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/error.hpp"
#include "cellrt/image.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/workload.hpp"

namespace {

using namespace cellrt;
using bench::median;
namespace cluster = cli::cluster;

struct Point {
    std::string scene, config, dispatch;
    int packet;
    unsigned workers;
    double seconds;
    // Summed over workers, each the median over frames: time tracing packets, time from the frame's
    // start to each worker's start, time from each worker's finish to the frame's end.
    double busy_seconds, started_seconds, waiting_seconds;
    // The same three as shares of workers x the frame, all of one round: the one whose frame time is
    // the median (of an even count, the upper middle one), so that with the rest ("between packets")
    // they make the whole. Shares of the medians above, taken over rounds apart, added up to 1.03
    // (found by audit, 2026-12-07).
    double tracing_share, waking_share, waiting_share;
    // Against the fewest workers, the median over rounds of each round's ratio: a shared machine's
    // speed drifts between rounds more than within one (its two frames are drawn back to back).
    double efficiency;         // t(first) first / (t(N) N)
    double packet_time_ratio;  // busy(N) / busy(first): how much longer the same packets took
    std::uint64_t rays;
    // `auto`: what its route chose over all of the structure's frames in the run, every dispatch mode
    // and packet size (its "routed" setting); empty for other structures.
    std::string routed;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(Point, scene, config, dispatch, packet, workers, seconds, busy_seconds,
                                   started_seconds, waiting_seconds, tracing_share, waking_share, waiting_share,
                                   efficiency, packet_time_ratio, rays, routed)

// The median over rounds r of f(r).
template <class F>
double median_of_rounds(int rounds, F&& f) {
    std::vector<double> v;
    for (int r = 0; r < rounds; ++r) v.push_back(f(static_cast<std::size_t>(r)));
    return median(v);
}

struct Options {
    std::string scenes_dir = "../shared/scenes";
    std::vector<std::string> scenes{"sponza", "sibenik", "bunny", "teapot", "builtin:city", "builtin:forest"};
    std::vector<std::string> configs{"embree:single", "kd+auto", "bih+auto", "kd:branched"};
    std::vector<std::string> dispatches{"pull", "mailbox"};
    std::vector<int> packets{2, 8, 16};
    std::vector<unsigned> workers;  // sorted; repeats refused
    int repeats = 3;
    std::string size = "512x512";
    ShadingOptions shading;  // every frame's, the yardstick's too
    std::string csv_path, json_path;
    bool overwrite = false;
    bool scenes_named = false;  // --scenes given: a scene not found is an error, not skipped
    int idle_spin = static_cast<int>(kDefaultIdleSpin.count());
    bool pin = false;
};

// Reads the command line into `o`; returns the exit status where the program ends there (--help, a bad
// option), as CLI11_PARSE would. A bad --shading, --size or configuration fails on every process
// (cluster.hpp).
std::optional<int> parse_options(int argc, char** argv, Options& o) {
    CLI::App app{"cellrt scaling study: seconds per frame vs workers, dispatch and packet size, Embree alongside"};
    app.add_option("--scenes-dir", o.scenes_dir, "Folder of the shared scenes")->capture_default_str();
    app.add_option("--scenes", o.scenes, "Shared scene names or builtin:... specs")->capture_default_str();
    app.add_option("--configs", o.configs, "KIND[:TRAVERSAL][+SIMD]; the first embree one is the yardstick")
        ->capture_default_str();
    // Checked here, so that CLI11 names the option in front of the library's message.
    app.add_option("--dispatch", o.dispatches, "Dispatch modes")
        ->capture_default_str()
        ->check([](const std::string& d) {
            try {
                parse_dispatch(d);
                return std::string();
            } catch (const Error& e) {
                return std::string(e.what());
            }
        });
    app.add_option("--packets", o.packets, "Packet edges P (P x P rays)")
        ->capture_default_str()
        ->check(CLI::Range(1, kMaxPacket));
    app.add_option("--workers", o.workers, "Worker counts (default 1..cores; under MPI rank 0's cores)");
    app.add_option("--repeats", o.repeats, "Timed frames per point (median)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    app.add_option("--size", o.size, "Image size WxH (the study's: 512x512)")->capture_default_str();
    std::string shading = to_string(o.shading.shading);
    app.add_option("--shading", shading,
                   "direct: one shadow ray per hit (the study's); ao: ambient occlusion; diffuse: one bounce lit "
                   "by the light")
        ->capture_default_str();
    auto* ao_samples = app.add_option("--ao-samples", o.shading.ao_samples, "AO rays per hit, with --shading ao")
                           ->capture_default_str()
                           ->check(CLI::Range(1, kMaxAoSamples));
    app.add_option("--idle-spin-us", o.idle_spin, "Microseconds the workers poll for the next frame before sleeping")
        ->capture_default_str()
        ->check(CLI::Range(0, 1000000));
    app.add_flag("--pin", o.pin, "Pin worker i to core i (mailbox: the master to core 0, worker i to core i + 1)");
    app.add_option("--csv", o.csv_path, "Write every point as CSV")->check(bench::non_empty_path());
    app.add_option("--json", o.json_path, "Write every point as JSON")->check(bench::non_empty_path());
    app.add_flag("--overwrite", o.overwrite, "Replace existing --csv and --json files");
    cluster::add_bench_options(app);
    cluster::strict_numbers(app);
    if (const int status = cluster::parse(app, argc, argv); status >= 0) return status;
    cluster::same_command_line("a sweep", {"--scenes-dir"});
    cluster::together([&] {
        try {
            o.shading.shading = parse_shading(shading);
        } catch (const Error& e) {
            // the library names the value, the user typed the option
            throw Error("--shading: " + std::string(e.what()));
        }
        // Another shading casts no AO rays: the rows would record samples that were never taken.
        if (ao_samples->count() > 0 && o.shading.shading != Shading::ao) throw Error("--ao-samples needs --shading ao");
        parse_image_size("--size", o.size);
        bench::check_configs(o.configs);
        cluster::check_no_repeats("--configs", o.configs);
        cluster::check_no_repeats("--scenes", o.scenes);
        cluster::check_no_repeats("--dispatch", o.dispatches);
        cluster::check_no_repeats("--packets", o.packets);
        cluster::check_no_repeats("--workers", o.workers);
        for (const unsigned w : o.workers)
            if (w < 1 || w > kMaxWorkers)
                throw Error("--workers " + std::to_string(w) + " must lie in [1, " + std::to_string(kMaxWorkers) + "]");
    }, "checking the options");
    o.scenes_named = app.count("--scenes") > 0;
    // Every process measures the same worker counts, so that the points are those of one process.
    const unsigned cores = static_cast<unsigned>(std::stoul(cluster::broadcast(std::to_string(cluster::cores()))));
    if (o.workers.empty())
        for (unsigned w = 1; w <= cores; ++w) o.workers.push_back(w);
    std::sort(o.workers.begin(), o.workers.end());  // efficiencies are against the fewest
    return std::nullopt;
}

// The first embree configuration, which every table is a ratio to; empty where there is none.
std::string yardstick_of(const std::vector<std::string>& configs) {
    for (const std::string& c : configs)
        if (parse_accel_config(c).kind == "embree") return c;
    return {};
}

// One worker count's timed frames, one figure a round; the loads are summed over its workers.
struct Rounds {
    std::vector<double> seconds, busy, started, waiting;
};

// The timed frames of one scene, structure, dispatch and packet size, by worker count.
struct Timings {
    std::map<unsigned, Rounds> by_workers;
    std::uint64_t rays = 0;  // a frame's, the same for every worker count
};

// A warm-up frame per structure and worker count, then --repeats rounds, each over the structures and,
// within each, over the worker counts: interleaved, so that a machine whose speed drifts (shared hosts
// do) shifts every structure and count alike, and ratios to the yardstick and efficiencies hold. (Run
// one structure after another, `bvh:packet`'s speed over Embree's on the bunny's 384 x 384 direct
// frames spread from 1.25 to 1.69 over six runs; interleaved, from 1.24 to 1.32 over four:
// docs/figures/route_cover.)
std::vector<Timings> timed_frames(const Scene& scene, std::span<const std::unique_ptr<Accelerator>> accels,
                                  RenderOptions ro, const Options& o) {
    Image frame;  // kept from frame to frame, as a renderer keeps its frame buffer
    for (const auto& accel : accels)
        for (unsigned w : o.workers) {
            ro.threads = w;
            render(scene, *accel, ro, frame);
        }
    std::vector<Timings> timings(accels.size());
    RenderStats st;
    for (int r = 0; r < o.repeats; ++r)
        for (std::size_t a = 0; a < accels.size(); ++a)
            for (unsigned w : o.workers) {
                ro.threads = w;
                // Frames drawn back to back, as a renderer draws them: the timed frame follows one with
                // the same structure and workers, so it finds the structure in the caches and the workers
                // still polling (RenderOptions::idle_spin), not asleep after other worker counts.
                render(scene, *accels[a], ro, frame);
                render(scene, *accels[a], ro, frame, &st);
                Timings& t = timings[a];
                Rounds& rounds = t.by_workers[w];
                rounds.seconds.push_back(st.seconds);
                double b = 0.0, s = 0.0, e = 0.0;
                for (const WorkerLoad& l : st.workers) {
                    b += l.busy_seconds;
                    s += l.started_seconds;
                    e += std::max(0.0, st.seconds - l.finished_seconds);
                }
                rounds.busy.push_back(b);
                rounds.started.push_back(s);
                rounds.waiting.push_back(e);
                t.rays = st.primary_rays + st.secondary_rays;
            }
    return timings;
}

// The points of one scene, structure, dispatch and packet size, a worker count each, appended to
// `points` with a progress line each on stderr.
void add_points(const Timings& t, const std::string& scene, const std::string& config, const std::string& dispatch,
                int packet, const std::string& routed, const Options& o, std::vector<Point>& points) {
    const unsigned first = o.workers.front();
    const Rounds& base = t.by_workers.at(first);
    for (unsigned w : o.workers) {
        const Rounds& rounds = t.by_workers.at(w);
        const double efficiency = median_of_rounds(o.repeats, [&](std::size_t r) {
            return base.seconds[r] * first / (rounds.seconds[r] * w);
        });
        const double packet_time_ratio =
            median_of_rounds(o.repeats, [&](std::size_t r) { return rounds.busy[r] / base.busy[r]; });
        std::vector<std::size_t> order(rounds.seconds.size());
        std::iota(order.begin(), order.end(), std::size_t{0});
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return rounds.seconds[a] < rounds.seconds[b]; });
        const std::size_t m = order[order.size() / 2];
        const double all = rounds.seconds[m] * w;
        points.push_back({scene, config, dispatch, packet, w, median(rounds.seconds), median(rounds.busy),
                          median(rounds.started), median(rounds.waiting), rounds.busy[m] / all,
                          rounds.started[m] / all, rounds.waiting[m] / all, efficiency, packet_time_ratio, t.rays,
                          routed});
        std::fprintf(stderr, "%s %s %s %dx%d %u workers: %.4f s\n", scene.c_str(), config.c_str(), dispatch.c_str(),
                     packet, packet, w, points.back().seconds);
    }
}

// Every point measured, and the names of the scenes that were there.
struct Study {
    std::vector<Point> points;
    std::vector<std::string> scene_names;
};

// One scene's points: every structure this binary has, dispatch mode and packet size, in that nesting
// (each structure is built once, all of them before the frames, which interleave them for every
// dispatch mode and packet size), as {"scene": its name, "points": [...]}.
nlohmann::json measure_scene(const Scene& scene, const Options& o) {
    const auto [width, height] = parse_image_size("--size", o.size);
    std::vector<std::string> names;
    std::vector<std::unique_ptr<Accelerator>> accels;
    for (const std::string& cfg_text : o.configs) {
        const AccelConfig cfg = parse_accel_config(cfg_text);
        if (!bench::built_in(cfg.kind)) continue;
        names.push_back(cfg_text);
        accels.push_back(make_accelerator(scene.triangles, cfg));
    }
    std::vector<std::vector<Timings>> timings;  // per dispatch and packet size, per structure
    for (const std::string& d : o.dispatches)
        for (int p : o.packets) {
            RenderOptions ro;
            ro.width = width;
            ro.height = height;
            ro.packet = p;
            ro.dispatch = parse_dispatch(d);
            ro.idle_spin = std::chrono::microseconds(o.idle_spin);
            ro.pin = o.pin;
            ro.shading = o.shading;
            timings.push_back(timed_frames(scene, accels, ro, o));
        }
    // The points in the order of one structure at a time, as the tables and files list them.
    std::vector<Point> points;
    for (std::size_t a = 0; a < accels.size(); ++a) {
        const std::string routed = accels[a]->stats().setting("routed").value_or("");
        std::size_t i = 0;
        for (const std::string& d : o.dispatches)
            for (int p : o.packets) add_points(timings[i++][a], scene.name, names[a], d, p, routed, o, points);
    }
    return {{"scene", scene.name}, {"points", points}};
}

// Every scene found, a run of the sweep each (bench_cluster.hpp).
Study measure(const Options& o) {
    Study study;
    const std::vector<std::string> specs = bench::found_scenes(o.scenes_dir, o.scenes, o.scenes_named);
    std::map<std::string, std::string> named;  // scene name -> spec
    std::string twice;                         // the refusal of a second scene of one name, on the leader
    cluster::sweep(
        specs.size(), [&](std::size_t i) { return measure_scene(load_scene(specs[i]), o).dump(); },
        [&](std::size_t i, const std::string& result) {
            const nlohmann::json scene = nlohmann::json::parse(result);
            const std::string name = scene["scene"].get<std::string>();
            // The tables and the yardstick's figures look points up by scene: two scenes of one name
            // showed the first one's figures twice (found by audit, 2026-12-07), as cache-study refuses.
            if (const auto [at, fresh] = named.emplace(name, specs[i]); !fresh && twice.empty())
                twice = specs[i] + " and " + at->second + " are both the scene '" + name +
                        "', and the results name their rows by scene: give one view file another \"name\"";
            study.scene_names.push_back(name);
            for (const nlohmann::json& point : scene["points"]) study.points.push_back(point.get<Point>());
        },
        "measuring the scenes");
    // Refused on every rank at once: the leader alone throwing left the others in a collective.
    cluster::together([&] { if (!twice.empty()) throw Error(twice); }, "naming the scenes");
    return study;
}

const Point* find(const std::vector<Point>& points, const std::string& scene, const std::string& config,
                  const std::string& d, int p, unsigned w) {
    for (const Point& pt : points)
        if (pt.scene == scene && pt.config == config && pt.dispatch == d && pt.packet == p && pt.workers == w)
            return &pt;
    return nullptr;
}

// The shading as the tables' headings name it.
std::string shading_label(const ShadingOptions& s) {
    const std::string name = std::string(to_string(s.shading)) + " shading";
    return s.shading == Shading::ao ? name + ", " + std::to_string(s.ao_samples) + " AO rays per hit" : name;
}

// Shaped like the study's: rows scenes, columns workers, seconds per frame with cellrt's rays/s over
// the yardstick's, and the parallel efficiency at the most workers.
void print_seconds_table(const Study& study, const Options& o, const std::string& yardstick,
                         const std::string& config, const std::string& d, int p) {
    const unsigned most = o.workers.back();
    std::printf("\n### %s, %s dispatch, %dx%d packets, %s: seconds per frame (rays/s ÷ %s)\n\n| scene |",
                config.c_str(), d.c_str(), p, p, shading_label(o.shading).c_str(),
                yardstick.empty() ? "Embree" : yardstick.c_str());
    for (unsigned w : o.workers) std::printf(" %u |", w);
    std::printf(" efficiency at %u |\n|---|", most);
    for (std::size_t i = 0; i <= o.workers.size(); ++i) std::printf("---|");
    std::printf("\n");
    for (const std::string& scene : study.scene_names) {
        std::printf("| %s |", detail::markdown_cell(scene).c_str());
        for (unsigned w : o.workers) {
            const Point* pt = find(study.points, scene, config, d, p, w);
            const Point* y = yardstick.empty() ? nullptr : find(study.points, scene, yardstick, d, p, w);
            if (!pt) std::printf(" – |");
            else if (y) std::printf(" %.4f (%.2f×) |", pt->seconds, y->seconds / pt->seconds);
            else std::printf(" %.4f |", pt->seconds);
        }
        const Point* last = find(study.points, scene, config, d, p, most);
        if (last) std::printf(" %.2f |\n", last->efficiency);
        else std::printf(" – |\n");
    }
}

// The workers' time at the most workers (most x seconds), in shares: tracing packets, and the
// schedule's parts; efficiency is about the tracing share over the packet time.
void print_time_shares(const Study& study, const Options& o, const std::string& config, const std::string& d, int p) {
    const unsigned one = o.workers.front(), most = o.workers.back();
    std::printf("\nWhere the %u workers' time went (shares of %u × the frame):\n\n"
                "| scene | tracing | waking | between packets | waiting at the end | packet time %u ÷ %u |\n"
                "|---|---|---|---|---|---|\n",
                most, most, most, one);
    for (const std::string& scene : study.scene_names) {
        const Point* last = find(study.points, scene, config, d, p, most);
        if (!last) continue;
        const double tracing = last->tracing_share, waking = last->waking_share, waiting = last->waiting_share;
        std::printf("| %s | %.3f | %.3f | %.3f | %.3f | %.3f |\n", detail::markdown_cell(scene).c_str(), tracing, waking,
                    std::max(0.0, 1.0 - tracing - waking - waiting), waiting, last->packet_time_ratio);
    }
}

// Every point, with the run's shading (ao_samples only for ao), `auto`'s route (routed) and the yardstick's seconds for the same
// scene, dispatch, packet size and workers where it was measured.
nlohmann::json points_json(const std::vector<Point>& points, const std::string& yardstick,
                           const ShadingOptions& shading) {
    nlohmann::json out = nlohmann::json::array();
    for (const Point& pt : points) {
        nlohmann::json j{{"scene", pt.scene},   {"config", pt.config},   {"dispatch", pt.dispatch},
                         {"packet", pt.packet}, {"shading", to_string(shading.shading)},
                         {"workers", pt.workers}, {"seconds", pt.seconds},
                         {"busy_seconds", pt.busy_seconds}, {"started_seconds", pt.started_seconds},
                         {"waiting_seconds", pt.waiting_seconds}, {"tracing_share", pt.tracing_share},
                         {"waking_share", pt.waking_share}, {"waiting_share", pt.waiting_share},
                         {"efficiency", pt.efficiency},
                         {"packet_time_ratio", pt.packet_time_ratio}, {"rays", pt.rays}};
        if (shading.shading == Shading::ao) j["ao_samples"] = shading.ao_samples;
        if (!pt.routed.empty()) j["routed"] = pt.routed;
        if (const Point* y =
                yardstick.empty() ? nullptr : find(points, pt.scene, yardstick, pt.dispatch, pt.packet, pt.workers))
            j["embree_seconds"] = y->seconds;
        out.push_back(j);
    }
    return out;
}

// The JSON rows as CSV, a column each; ao_samples and embree_seconds are empty where a row lacks them.
std::string csv_of(const nlohmann::json& rows) {
    std::ostringstream csv;
    csv << "scene,config,dispatch,packet,shading,ao_samples,workers,seconds,busy_seconds,started_seconds,"
           "waiting_seconds,efficiency,packet_time_ratio,rays,embree_seconds\n";
    for (const auto& j : rows) {
        const auto optional = [&j](const char* key) { return j.contains(key) ? j[key].dump() : std::string(); };
        csv << detail::csv_field(j["scene"].get<std::string>()) << ',' << detail::csv_field(j["config"].get<std::string>())
            << ',' << j["dispatch"].get<std::string>() << ',' << j["packet"] << ',' << j["shading"].get<std::string>() << ','
            << optional("ao_samples") << ',' << j["workers"] << ',' << j["seconds"] << ',' << j["busy_seconds"] << ','
            << j["started_seconds"] << ',' << j["waiting_seconds"] << ',' << j["efficiency"] << ','
            << j["packet_time_ratio"] << ',' << j["rays"] << ',' << optional("embree_seconds") << '\n';
    }
    return csv.str();
}

int run(int argc, char** argv) {
    Options o;
    if (const std::optional<int> status = parse_options(argc, argv, o)) return *status;
    std::vector<std::string> named;
    for (const std::string& name : o.scenes) named.push_back(bench::scene_file(o.scenes_dir, name));
    bench::check_results_paths({{"--json", o.json_path}, {"--csv", o.csv_path}}, o.overwrite, named);
    const std::string yardstick = yardstick_of(o.configs);
    const Study study = measure(o);
    // One table per configuration, dispatch and packet size; then where the time of the most workers went.
    if (cluster::leader())
        for (const std::string& config : o.configs)
            for (const std::string& d : o.dispatches)
                for (int p : o.packets) {
                    print_seconds_table(study, o, yardstick, config, d, p);
                    print_time_shares(study, o, config, d, p);
                }
    const nlohmann::json out = points_json(study.points, yardstick, o.shading);
    if (!o.json_path.empty()) bench::write_results(o.json_path, out.dump(1) + "\n", o.overwrite);
    if (!o.csv_path.empty()) bench::write_results(o.csv_path, csv_of(out), o.overwrite);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return cellrt::bench::main_on_cluster(argc, argv, "cellrt_scaling", run); }
