// `cellrt profile SCENE ...`: instruction-level statistics of one frame rendered single-threaded, for
// the whole render and for the traversal alone (the study's Tables 5-3, 5-4 and 5-7), from the
// processor's counters or, where it exposes none, from callgrind's simulation (docs/PROFILE.md).
//
// Under callgrind the frame is rendered by a second run of this program (hidden option
// --callgrind-child), once per region, so the numbers come from the same code the user runs.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <optional>

#include "profile/frame_profile.hpp"
#include "profile/hardware_counters.hpp"
#include "cellrt/error.hpp"
#include "cellrt/loaders.hpp"
#include "core/files.hpp"
#include "cellrt/scene.hpp"
#include "cli.hpp"

namespace cellrt::cli {
namespace {

// Image edge under callgrind unless --size says otherwise: the simulated render runs about 50 times
// slower than the native one.
constexpr int kCallgrindEdge = 128;
constexpr int kTimedRenders = 5;

struct ProfileOptions {
    std::string scene, size, method = "auto", json, child;
    bool overwrite = false;
    int packet = RenderOptions{}.packet;
    AccelOptions accel;
};

std::string region_name(profile::Region r) { return r == profile::Region::render ? "render" : "traversal"; }

// This program, run again on the same frame for callgrind to measure `region`.
std::vector<std::string> child_command(const std::string& scene, const AccelConfig& c, const RenderOptions& ro,
                                       profile::Region region) {
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("cannot locate this program through /proc/self/exe: " + ec.message());
    std::vector<std::string> args = {self.string(), "profile", scene, "--accel", c.kind, "--simd", c.simd};
    if (!c.traversal.empty()) args.insert(args.end(), {"--traversal", c.traversal});
    for (const auto& [name, value] : c.params) args.insert(args.end(), {"-P", name + "=" + value});
    args.insert(args.end(), {"--threads", std::to_string(c.threads), "--size",
                             std::to_string(ro.width) + "x" + std::to_string(ro.height), "--packet",
                             std::to_string(ro.packet), "--callgrind-child", region_name(region)});
    return args;
}

double process_cpu_seconds() {
    timespec t{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double per(std::uint64_t count, std::uint64_t rays) { return rays ? static_cast<double>(count) / rays : 0.0; }

std::string with_commas(std::uint64_t v) {
    std::string digits = std::to_string(v), out;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i && (digits.size() - i) % 3 == 0) out += ',';
        out += digits[i];
    }
    return out;
}

std::string number_or_na(const std::optional<double>& v, const char* format) {
    if (!v) return "n/a";
    char buf[32];
    std::snprintf(buf, sizeof buf, format, *v);
    return buf;
}

void print_row(const char* label, const std::string& render, const std::string& traversal) {
    std::printf("%-22s %18s %18s\n", label, render.c_str(), traversal.c_str());
}

void print_report(const profile::RegionCounts& c, const TraversalCounters& work, bool counts_work) {
    const profile::EventCounts& r = c.render;
    const profile::EventCounts& t = c.traversal;
    auto count = [](const std::optional<std::uint64_t>& v) { return v ? with_commas(*v) : std::string("n/a"); };
    auto fixed = [](double v, const char* format) { return number_or_na(v, format); };
    auto cycles_per_ray = [&](const profile::EventCounts& e) {
        return number_or_na(e.cycles ? std::optional(per(*e.cycles, work.rays)) : std::nullopt, "%.1f");
    };
    print_row("", "whole render", "traversal");
    print_row("instructions", with_commas(r.instructions), with_commas(t.instructions));
    print_row("cycles", count(r.cycles), count(t.cycles));
    print_row("IPC", number_or_na(r.ipc(), "%.3f"), number_or_na(t.ipc(), "%.3f"));
    print_row("CPI", number_or_na(r.cpi(), "%.3f"), number_or_na(t.cpi(), "%.3f"));
    print_row("branches", with_commas(r.branches), with_commas(t.branches));
    print_row("mispredictions", with_commas(r.mispredictions), with_commas(t.mispredictions));
    print_row("mispredicted", fixed(100.0 * per(r.mispredictions, r.branches), "%.2f%%"),
              fixed(100.0 * per(t.mispredictions, t.branches), "%.2f%%"));
    std::printf("per ray\n");
    print_row("  instructions", fixed(per(r.instructions, work.rays), "%.1f"),
              fixed(per(t.instructions, work.rays), "%.1f"));
    print_row("  cycles", cycles_per_ray(r), cycles_per_ray(t));
    print_row("  mispredictions", fixed(per(r.mispredictions, work.rays), "%.3f"),
              fixed(per(t.mispredictions, work.rays), "%.3f"));
    // Embree counts rays only (AccelStats::counts_work): its work reads n/a, not a measured zero.
    auto work_per_ray = [&](std::uint64_t n) { return counts_work ? fixed(per(n, work.rays), "%.2f") : "n/a"; };
    print_row("  nodes", "", work_per_ray(work.nodes));
    print_row("  leaves", "", work_per_ray(work.leaves));
    print_row("  triangles", "", work_per_ray(work.triangles));
}

nlohmann::json to_json(const profile::EventCounts& c, std::uint64_t rays) {
    auto optional = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(); };
    nlohmann::json j = {{"instructions", c.instructions},
                        {"cycles", c.cycles ? nlohmann::json(*c.cycles) : nlohmann::json()},
                        {"ipc", optional(c.ipc())},
                        {"cpi", optional(c.cpi())},
                        {"branches", c.branches},
                        {"mispredictions", c.mispredictions}};
    j["per_ray"] = {{"instructions", per(c.instructions, rays)},
                    {"cycles", c.cycles ? nlohmann::json(per(*c.cycles, rays)) : nlohmann::json()},
                    {"mispredictions", per(c.mispredictions, rays)}};
    return j;
}

int run_child(const ProfileOptions& o) {
    const Scene scene = load_scene(o.scene);
    RenderOptions ro;
    std::tie(ro.width, ro.height) = parse_image_size("--size", o.size);
    ro.packet = o.packet;
    const auto accel = make_accelerator(scene.triangles, o.accel.config());
    profile::render_under_callgrind(scene, *accel, ro);
    return 0;
}

// Whether the counts come from the processor's counters (else from callgrind's simulation), refusing
// at the start a method that cannot run here.
bool use_hardware_counters(const std::string& method) {
    bool hardware = method == "hardware";
    if (method == "auto") {
        std::string why;
        hardware = profile::HardwareCounters::open(profile::HardwareCounters::Threads::calling_and_new, why)
                       .has_value();
        if (!hardware) std::printf("%s; falling back to callgrind's simulation\n", why.c_str());
    } else if (hardware) {
        profile::HardwareCounters::open_or_throw(profile::HardwareCounters::Threads::calling_and_new);
    }
    if (!hardware && profile::find_valgrind().empty())
        throw Error("valgrind, which counts without hardware counters, is not on PATH (install the valgrind "
                    "package, see packages.txt)");
    if (!hardware) profile::temp_folder();  // checked before the work, not when callgrind starts
    return hardware;
}

// The structure's configuration as profiled: under callgrind, with a SIMD set valgrind can run.
AccelConfig profiled_config(const AccelOptions& accel, bool hardware) {
    AccelConfig config = accel.config();
    if (hardware) return config;
    std::string note;
    try {
        config = profile::config_for_callgrind(config, note);
    } catch (const Error& e) {
        throw Error(std::string("--simd: ") + e.what());
    }
    if (!note.empty()) std::printf("%s\n", note.c_str());
    return config;
}

// One render thread, at the view file's size with the counters and kCallgrindEdge under callgrind,
// unless --size says otherwise.
RenderOptions profiled_frame(const Scene& scene, const ProfileOptions& o, bool hardware) {
    RenderOptions ro;
    ro.width = ro.height = kCallgrindEdge;
    if (hardware) ro.width = scene.width, ro.height = scene.height;
    if (!o.size.empty()) std::tie(ro.width, ro.height) = parse_image_size("--size", o.size);
    ro.threads = 1;
    ro.packet = o.packet;
    // The frames counted with the processor's counters run in a Cancellable section (run_profile):
    // they stop at the next packet on a signal.
    ro.cancel = &g_cancel;
    return ro;
}

void print_setup(const Scene& scene, const AccelStats& st, const AccelConfig& config, const RenderOptions& ro,
                 bool hardware, bool default_size) {
    std::printf("profile                %s: %zu triangles, %s (%s%s), %dx%d, packet %d, 1 render thread\n",
                scene.name.c_str(), scene.triangles.size(), st.name.c_str(), st.traversal.c_str(),
                st.simd_lanes ? (", " + config.simd + ", " + std::to_string(st.simd_lanes) + " lanes").c_str() : "",
                ro.width, ro.height, ro.packet);
    if (hardware)
        std::printf("counts                 hardware counters (perf_event_open), user space only\n");
    else
        std::printf("counts                 callgrind --branch-sim=yes: exact instructions, simulated predictor, no "
                    "cycles%s\n",
                    default_size ? "; 128x128 is the default size under callgrind" : "");
    std::fflush(stdout);
}

// The native render's time: CPU time of the process, which a busy machine's other work does not
// inflate as it does wall time; best of kTimedRenders.
double native_render_seconds(const Scene& scene, const Accelerator& accel, const RenderOptions& ro) {
    double best = 0.0;
    for (int i = 0; i < kTimedRenders; ++i) {
        const double start = process_cpu_seconds();
        render(scene, accel, ro);
        const double seconds = process_cpu_seconds() - start;
        best = i == 0 ? seconds : std::min(best, seconds);
    }
    return best;
}

// A native render with the kernels' work counters on: they change the kernels' code, so they are
// never on while instructions are counted.
RenderStats counted_work(const Scene& scene, const Accelerator& accel, const RenderOptions& ro) {
    RenderStats work;
    RenderOptions counted = ro;
    counted.count = true;
    render(scene, accel, counted, &work);
    return work;
}

// The events of the whole render and of the traversal alone: from the counters in this process, or
// from callgrind running this program again once per region.
profile::RegionCounts event_counts(const Scene& scene, const Accelerator& accel, const RenderOptions& ro,
                                   const std::string& scene_spec, const AccelConfig& config, bool hardware) {
    if (hardware) return profile::measure_with_counters(scene, accel, ro);
    profile::RegionCounts counts;
    for (const profile::Region r : {profile::Region::render, profile::Region::traversal}) {
        profile::CallgrindOptions options = profile::callgrind_options(r);
        options.cancel = &g_cancel;  // a signal kills the run and removes its folder (Cancellable below)
        const profile::EventCounts c = profile::run_callgrind(child_command(scene_spec, config, ro, r), options);
        (r == profile::Region::render ? counts.render : counts.traversal) = c;
    }
    return counts;
}

// What one profile measured, for the JSON file.
struct Profile {
    AccelStats structure;
    AccelConfig config;
    RenderOptions frame;
    bool hardware = false;
    double native_seconds = 0.0;
    RenderStats work;
    TraversalCounters all;  // primary and shadow rays together
    profile::RegionCounts counts;
};

nlohmann::json profile_json(const Scene& scene, const ProfileOptions& o, const Profile& p) {
    const AccelStats& st = p.structure;
    const TraversalCounters& all = p.all;
    nlohmann::json j = {{"scene", scene.name},
                        {"triangles", scene.triangles.size()},
                        {"accel", st.name},
                        {"traversal", st.traversal},
                        {"simd", st.simd_lanes ? p.config.simd : "off"},
                        {"simd_lanes", st.simd_lanes ? std::to_string(st.simd_lanes) : "off"},
                        {"params", o.accel.params},
                        {"width", p.frame.width},
                        {"height", p.frame.height},
                        {"packet", p.frame.packet},
                        {"method", p.hardware ? "hardware" : "callgrind"},
                        {"native_render_cpu_seconds", p.native_seconds}};
    j["rays"] = {{"primary", p.work.primary_rays}, {"shadow", p.work.secondary_rays}, {"all", all.rays}};
    if (st.counts_work)
        j["work"] = {{"nodes", all.nodes},
                     {"leaves", all.leaves},
                     {"triangles", all.triangles},
                     {"per_ray",
                      {{"nodes", per(all.nodes, all.rays)},
                       {"leaves", per(all.leaves, all.rays)},
                       {"triangles", per(all.triangles, all.rays)}}}};
    else
        j["work"] = nullptr;  // Embree counts rays only
    j["regions"] = {{"render", to_json(p.counts.render, all.rays)},
                    {"traversal", to_json(p.counts.traversal, all.rays)}};
    return j;
}

int run_profile(const ProfileOptions& o) {
    Profile p;
    p.hardware = use_hardware_counters(o.method);
    if (!o.json.empty()) {
        check_output_file(o.json, o.overwrite);
        check_distinct_files({{"--json", o.json}}, scene_files(o.scene));
    }
    if (o.packet < 1 || o.packet > kMaxPacket)
        throw Error("--packet " + std::to_string(o.packet) + " must lie in [1, " + std::to_string(kMaxPacket) + "]");
    p.config = profiled_config(o.accel, p.hardware);
    if (!o.size.empty()) parse_image_size("--size", o.size);
    check_structure(o.accel);
    const Scene scene = load_scene(o.scene);
    p.frame = profiled_frame(scene, o, p.hardware);
    const auto accel = build_structure(scene.triangles, p.config, o.accel);
    p.structure = accel->stats();
    print_setup(scene, p.structure, p.config, p.frame, p.hardware, o.size.empty());

    p.native_seconds = native_render_seconds(scene, *accel, p.frame);
    p.work = counted_work(scene, *accel, p.frame);
    p.all = p.work.primary;
    p.all += p.work.secondary;
    const Cancellable cancellable;  // valgrind's runs and the JSON's write: nothing left behind
    p.counts = event_counts(scene, *accel, p.frame, o.scene, p.config, p.hardware);

    std::printf("rays                   %s primary + %s shadow = %s; native render %.4f s CPU (best of %d)\n",
                with_commas(p.work.primary_rays).c_str(), with_commas(p.work.secondary_rays).c_str(),
                with_commas(p.all.rays).c_str(), p.native_seconds, kTimedRenders);
    print_report(p.counts, p.all, p.structure.counts_work);
    if (!o.json.empty()) write_file_atomically(o.json, json_report(profile_json(scene, o, p)), o.overwrite);
    return 0;
}

}  // namespace

Runner add_profile(CLI::App& app) {
    auto o = std::make_shared<ProfileOptions>();
    auto* cmd = app.add_subcommand("profile", "Instructions, cycles, branches and mispredictions of one "
                                              "single-threaded frame: whole render and traversal alone "
                                              "(docs/PROFILE.md)");
    cmd->add_option("scene", o->scene, scene_help())->required();
    o->accel.add_to(*cmd, false);
    o->accel.threads_option->description("Build threads (0: all cores); the profiled frame renders on one thread");
    cmd->add_option("--size", o->size, "Image size WIDTHxHEIGHT (default: the view file's; 128x128 under callgrind)")
        ->check(non_empty());
    cmd->add_option("--packet", o->packet, "Packet edge P: the renderer traces P x P rays at a time")
        ->capture_default_str();
    cmd->add_option("--method", o->method, "Where counts come from: hardware (perf_event_open), callgrind, or auto "
                                           "(hardware where available)")
        ->check(CLI::IsMember({"auto", "hardware", "callgrind"}))
        ->capture_default_str();
    cmd->add_option("--json", o->json, "Also write the figures as JSON to this file")->check(non_empty());
    cmd->add_flag("--overwrite", o->overwrite, "Replace the JSON file if it exists");
    cmd->add_option("--callgrind-child", o->child, "Internal: render for callgrind to measure this region")
        ->check(CLI::IsMember({"render", "traversal"}))
        ->group("");
    return [o] { return o->child.empty() ? run_profile(*o) : run_child(*o); };
}

}  // namespace cellrt::cli
