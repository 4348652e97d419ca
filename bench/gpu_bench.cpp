// The CUDA backend against Embree on all of the host's cores, on the same rays (docs/GPU.md): a
// frame's primary rays and the rays its shading casts (shadow, AO, diffuse bounce; workload.hpp) at
// --size, for every device configuration; rays resident on the device (the kernel's own time, CUDA
// events) and, separately, host batches with their copies in and out; and the frame path, the whole
// frame made, traced and shaded on the device (render --device cuda), against cellrt's renderer on the
// host's cores. Every answer is compared with the host's exact one, every pixel with the host's image.
// Without a device it says so in one line and exits with status 3; where any answer or pixel differs,
// with status 4.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <thread>

#include <nlohmann/json.hpp>

#include "bench_common.hpp"
#include "cluster.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/device.hpp"
#include "cellrt/error.hpp"
#include "cellrt/image.hpp"
#include "cellrt/loaders.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "core/files.hpp"
#include "core/timer.hpp"
#include "cellrt/workload.hpp"

namespace {

using namespace cellrt;
using bench::median;

struct Options {
    std::string scenes_dir = "../shared/scenes";
    std::vector<std::string> scenes{"sponza", "sibenik", "bunny", "builtin:city"};
    std::vector<std::string> rays{"frame", "ao", "diffuse"};
    // The last three: memory mode (b), the study's caches in shared memory (its default layouts),
    // synchronous, and the kd-tree's with asynchronous access too.
    std::vector<std::string> configs{"kd:branched",
                                     "kd:branchless",
                                     "kd:rec",
                                     "bih:branched",
                                     "bih:branchless",
                                     "bih:branched@split=sah",
                                     "kd:branched@memory=shared",
                                     "bih:branched@memory=shared",
                                     "kd:branched@memory=shared,access=async"};
    std::string cpu_config = "embree";
    std::string size = "1920x1080", json_path;
    bool overwrite = false;
    int repeats = 5, ao_samples = 4;
    unsigned threads = 0;
};

struct Answers {
    std::vector<Hit> hits;
    std::vector<std::uint8_t> occluded;
};

// `rays` answered by `accel` on `threads` host threads, each a contiguous share in batches of 256.
double trace_host(const Accelerator& accel, std::span<const Ray> rays, bool closest, unsigned threads, Answers& out) {
    out.hits.resize(closest ? rays.size() : 0);
    out.occluded.resize(closest ? 0 : rays.size());
    const std::size_t share = (rays.size() + threads - 1) / threads;
    Timer timer;
    std::vector<std::thread> team;
    for (unsigned t = 0; t < threads; ++t)
        team.emplace_back([&, t] {
            const std::size_t end = std::min(rays.size(), (t + 1) * share);
            for (std::size_t i = t * share; i < end; i += 256) {
                const std::size_t n = std::min<std::size_t>(256, end - i);
                if (closest) accel.intersect(rays.subspan(i, n), std::span(out.hits).subspan(i, n));
                else accel.occluded(rays.subspan(i, n), std::span(out.occluded).subspan(i, n));
            }
        });
    for (std::thread& t : team) t.join();
    return timer.seconds();
}

std::size_t differing(const Answers& a, const Answers& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.hits.size(); ++i) n += !(a.hits[i] == b.hits[i]);
    for (std::size_t i = 0; i < a.occluded.size(); ++i) n += a.occluded[i] != b.occluded[i];
    return n;
}

struct Set {
    const char* name;
    std::span<const Ray> rays;
    bool closest;
    Answers exact;
};

void bench_rays(const Scene& scene, const std::string& kind, const Options& o, const DeviceInfo& gpu,
                nlohmann::json& out) {
    const auto [w, h] = parse_image_size("--size", o.size);
    const unsigned threads = o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency());
    const std::string exact_spec = "kd+auto";
    const auto exact = make_accelerator(scene.triangles, parse_accel_config(exact_spec));
    ShadingOptions shading;
    shading.shading = kind == "frame" ? Shading::direct : parse_shading(kind);
    shading.ao_samples = o.ao_samples;
    const FrameRays f = frame_rays(scene, w, h, 16, *exact, shading);
    Set sets[2] = {{"primary", f.primary, true, {}}, {to_string(f.secondary_kind), f.secondary, closest_hit(f.secondary_kind), {}}};
    for (Set& s : sets) trace_host(*exact, s.rays, s.closest, threads, s.exact);
    std::printf("\n### %s, %s rays, %dx%d: %zu primary + %zu %s\n\n| config | primary Grays/s | %s Grays/s | "
                "with copies Grays/s | answers ≠ exact | frame: kernel, Grays/s, × CPU frame | pixels ≠ CPU |\n"
                "|---|---|---|---|---|---|---|\n",
                scene.name.c_str(), kind.c_str(), w, h, f.primary.size(), f.secondary.size(), sets[1].name,
                sets[1].name);
    nlohmann::json row = {{"scene", scene.name}, {"rays", kind}, {"width", w}, {"height", h},
                          {"primary_rays", f.primary.size()}, {"secondary_rays", f.secondary.size()},
                          {"secondary_kind", sets[1].name}, {"device", gpu.name}, {"host_threads", threads}};
    // Embree (or --cpu-config) on every host core, the same rays.
    if (bench::built_in(parse_accel_config(o.cpu_config).kind)) {
        const auto cpu = make_accelerator(scene.triangles, parse_accel_config(o.cpu_config));
        for (Set& s : sets) {
            std::vector<double> t;
            Answers a;
            for (int k = 0; k < o.repeats; ++k) t.push_back(trace_host(*cpu, s.rays, s.closest, threads, a));
            row["cpu"][s.name] = {{"config", o.cpu_config}, {"seconds", median(t)},
                                  {"grays_per_s", s.rays.size() / median(t) * 1e-9}, {"differing", differing(a, s.exact)}};
        }
    }
    // The whole frame on the host's cores through cellrt's renderer (the exact configuration): the
    // image the device's frame path must give, and its time.
    RenderOptions ro;
    ro.width = w;
    ro.height = h;
    ro.threads = threads;
    ro.shading = shading;
    Image cpu_image;
    std::vector<double> cpu_frame;
    for (int k = 0; k < std::min(o.repeats, 3); ++k) {
        RenderStats rs;
        render(scene, *exact, ro, cpu_image, &rs);
        cpu_frame.push_back(rs.seconds);
    }
    row["cpu_frame"] = {{"config", exact_spec}, {"seconds", median(cpu_frame)}};
    const FrameShading frame = frame_shading(scene, PinholeCamera(scene.camera, w, h), shading);
    for (const std::string& spec : o.configs) {
        AccelConfig c = parse_accel_config(spec);
        const auto gpu_accel = make_device_accelerator(scene.triangles, c);
        nlohmann::json r = {{"config", spec}};
        for (Set& s : sets) {
            DeviceRayBatch batch(s.rays.size());
            batch.upload(s.rays);
            std::vector<double> kernel, copies;
            Answers a;
            for (int k = 0; k <= o.repeats; ++k) {  // the first pass warms up
                const double t = s.closest ? gpu_accel->intersect_resident(batch) : gpu_accel->occluded_resident(batch);
                if (k > 0) kernel.push_back(t);
            }
            for (int k = 0; k < o.repeats; ++k) {
                Timer timer;
                if (s.closest) {
                    a.hits.resize(s.rays.size());
                    gpu_accel->intersect(s.rays, a.hits);
                } else {
                    a.occluded.resize(s.rays.size());
                    gpu_accel->occluded(s.rays, a.occluded);
                }
                copies.push_back(timer.seconds());
            }
            Answers resident;
            if (s.closest) {
                resident.hits.resize(s.rays.size());
                batch.download_hits(resident.hits);
            } else {
                resident.occluded.resize(s.rays.size());
                batch.download_occluded(resident.occluded);
            }
            r[s.name] = {{"kernel_seconds", median(kernel)}, {"grays_per_s", s.rays.size() / median(kernel) * 1e-9},
                         {"with_copies_seconds", median(copies)},
                         {"with_copies_grays_per_s", s.rays.size() / median(copies) * 1e-9},
                         {"differing", differing(a, s.exact) + differing(resident, s.exact)}};
            if (row.contains("cpu")) r[s.name]["times_cpu"] = row["cpu"][s.name]["seconds"].get<double>() / median(kernel);
        }
        {
            // The frame path: every pixel made, traced and shaded on the device (render --device cuda).
            std::vector<Vec3> pixels(cpu_image.pixels.size());
            std::vector<double> kernel, whole;
            std::uint64_t frame_rays = 0;
            for (int k = 0; k <= o.repeats; ++k) {  // the first pass warms up
                TraversalCounters p, sec;
                const auto t = gpu_accel->render_frame(scene.triangles, frame, 0, 0, w, h, pixels, p, sec);
                frame_rays = p.rays + sec.rays;
                if (k == 0) continue;
                kernel.push_back(t.kernel_seconds);
                whole.push_back(t.seconds);
            }
            std::size_t differ = 0;
            for (std::size_t i = 0; i < pixels.size(); ++i)
                differ += std::memcmp(&pixels[i], &cpu_image.pixels[i], sizeof(Vec3)) != 0;
            r["frame"] = {{"kernel_seconds", median(kernel)},
                          {"with_copies_seconds", median(whole)},
                          {"rays", frame_rays},
                          {"grays_per_s", static_cast<double>(frame_rays) / median(kernel) * 1e-9},
                          {"times_cpu_frame", median(cpu_frame) / median(kernel)},
                          {"differing_pixels", differ}};
        }
        if (const DeviceCacheStats cs = gpu_accel->cache_stats(); cs.blocks > 0) {
            auto counts = [](const DeviceCacheCounts& c) {
                return nlohmann::json{{"hits", c.hits},
                                      {"misses", c.misses},
                                      {"evictions", c.evictions},
                                      {"torn", c.torn},
                                      {"unfilled", c.unfilled},
                                      {"prefetches", c.prefetches},
                                      {"touch_hits", c.touch_hits},
                                      // null, not 0, where no ray read the cache: 0 would read as the worst.
                                      {"hit_ratio", c.lookups() ? nlohmann::json(double(c.hits) / double(c.lookups()))
                                                                : nlohmann::json()}};
            };
            // Over every launch of this configuration on this scene, all ray sets together.
            const auto settings = gpu_accel->stats().settings;
            const auto memory = std::find_if(settings.begin(), settings.end(), [](const auto& kv) { return kv.first == "memory"; });
            r["shared_caches"] = {{"layout", memory != settings.end() ? memory->second : ""},
                                  {"blocks", cs.blocks},
                                  {"node_cache", counts(cs.node_cache)},
                                  {"triangle_cache", counts(cs.triangle_cache)}};
        }
        std::printf("| %s | %.3f | %.3f | %.3f / %.3f | %zu | %.2f ms, %.3f, %.1fx | %zu |\n", spec.c_str(),
                    r["primary"]["grays_per_s"].get<double>(), r[sets[1].name]["grays_per_s"].get<double>(),
                    r["primary"]["with_copies_grays_per_s"].get<double>(),
                    r[sets[1].name]["with_copies_grays_per_s"].get<double>(),
                    r["primary"]["differing"].get<std::size_t>() + r[sets[1].name]["differing"].get<std::size_t>(),
                    1e3 * r["frame"]["kernel_seconds"].get<double>(), r["frame"]["grays_per_s"].get<double>(),
                    r["frame"]["times_cpu_frame"].get<double>(), r["frame"]["differing_pixels"].get<std::size_t>());
        row["gpu"].push_back(r);
    }
    out.push_back(row);
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    CLI::App app{"cellrt's CUDA backend against Embree on the host's cores, the same rays"};
    app.add_option("--scenes-dir", o.scenes_dir, "Folder of the shared scenes")->capture_default_str();
    app.add_option("--scenes", o.scenes, "Shared scene names or builtin:... specs")->capture_default_str();
    app.add_option("--rays", o.rays, "Ray sets: frame (shadow), ao, diffuse")
        ->capture_default_str()
        ->check(CLI::IsMember({"frame", "ao", "diffuse"}));
    app.add_option("--configs", o.configs, "Device configurations KIND[:TRAVERSAL][@NAME=VALUE,...]")->capture_default_str();
    app.add_option("--cpu-config", o.cpu_config, "The host's yardstick, on every core")->capture_default_str();
    app.add_option("--size", o.size, "Frame size WxH")->capture_default_str();
    app.add_option("--ao-samples", o.ao_samples, "AO rays per hit")->capture_default_str()->check(CLI::Range(1, kMaxAoSamples));
    app.add_option("--repeats", o.repeats, "Timed passes (median)")->capture_default_str()->check(CLI::Range(1, 1000));
    app.add_option("--threads", o.threads, "Host threads for the yardstick (0: all)")->capture_default_str();
    app.add_option("--json", o.json_path, "Write every result as JSON")->check(bench::non_empty_path());
    app.add_flag("--overwrite", o.overwrite, "Replace an existing --json file");
    cli::cluster::start(argc, argv, "cellrt_gpu_bench");
    cli::cluster::strict_numbers(app);
    if (const int status = cli::cluster::parse(app, argc, argv); status >= 0) return status;
    try {
        if (!o.json_path.empty()) {
            check_output_file(o.json_path, o.overwrite);
            std::vector<std::string> specs;
            for (const std::string& name : o.scenes) specs.push_back(bench::scene_file(o.scenes_dir, name));
            check_distinct_files({{"--json", o.json_path}}, scene_files(specs));
        }
    } catch (const Error& e) {
        cli::cluster::print_error(e);
        return 1;
    }
    const DeviceInfo gpu = cuda_device_info();
    if (!gpu.present) {
        std::printf("cuda: no device (%s)\n", gpu.reason.c_str());
        return 3;
    }
    nlohmann::json out = nlohmann::json::array();
    bool written = false;
    try {
        for (const std::string& name : o.scenes)
            if (const auto spec = bench::scene_spec(o.scenes_dir, name)) {
                const Scene scene = load_scene(*spec);
                for (const std::string& kind : o.rays) {
                    bench_rays(scene, kind, o, gpu, out);
                    // Rewritten after every set, so that a run cut short keeps what it measured: the
                    // user's --overwrite decides the first time, the file is this run's after it.
                    if (!o.json_path.empty()) {
                        write_file_atomically(o.json_path, out.dump(1) + "\n", o.overwrite || written);
                        written = true;
                    }
                }
            }
    } catch (const Error& e) {
        std::fprintf(stderr, "cellrt_gpu_bench: error: %s\n", e.what());
        return 1;
    }
    // A wrong answer is a failure, not a figure: the device script reads the status, not the tables.
    // (Embree's own answers differ from cellrt's rule by rounding, docs/EMBREE.md: not counted.)
    std::size_t wrong = 0;
    for (const auto& row : out)
        for (const auto& r : row.value("gpu", nlohmann::json::array()))
            for (const auto& [name, set] : r.items())
                if (set.is_object())
                    wrong += set.value("differing", std::size_t{0}) + set.value("differing_pixels", std::size_t{0});
    if (wrong > 0) {
        std::fprintf(stderr, "cellrt_gpu_bench: %zu of the device's answers or pixels differ from the host's (the "
                             "tables' columns \"answers ≠ exact\" and \"pixels ≠ CPU\")\n", wrong);
        return cli::cluster::flushed(4);
    }
    return cli::cluster::flushed(0);
}
