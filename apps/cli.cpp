#include "cli.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "kernel/named.hpp"
#include "localstore/local_store.hpp"
#include "simd/isa.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cellrt/schedule.hpp"

namespace cellrt::cli {

std::atomic<bool> g_cancel{false};
std::atomic<bool> g_cancellable{false};

std::string scene_help() {
    std::string names;
    for (const auto& b : builtin_scenes()) names += (names.empty() ? "" : ", ") + b.name;
    return "Scene: VIEW.json, MESH.obj, MESH.ply, SCENE.gltf, SCENE.glb, or builtin:NAME[?tris=N&seed=S] (" + names + ")";
}

void AccelOptions::add_to(CLI::App& cmd, bool kind_optional, bool with_device) {
    std::string kinds, traversals;  // every kind's traversals, from the library (the default first)
    for (const auto& k : accelerator_kinds()) {
        kinds += (kinds.empty() ? "" : "|") + k;
        std::string own;
        for (const std::string& t : accelerator_traversals(k)) own += (own.empty() ? "" : "|") + t;
        traversals += (traversals.empty() ? "" : ", ") + k + ": " + own;
    }
    if (kind_optional) kind.clear();
    cmd.add_option("--accel", kind,
                   "Acceleration structure: " + kinds +
                       ", or a whole configuration KIND[:TRAVERSAL][+SIMD][@NAME=VALUE,...] as the benchmarks, the C "
                       "API and Python name it (the options below add to it)")
        ->capture_default_str()
        ->check(non_empty());
    traversal_option = cmd.add_option("--traversal", traversal,
                   "Traversal (" + traversals + "); implies --simd off")
                           ->check(non_empty());
    simd_option = cmd.add_option("--simd", simd,
                                 "SIMD ray packets: auto|off|portable|sse|avx2|avx512 (docs/PACKETS.md)")
                      ->capture_default_str();
    params_option =
        cmd.add_option("-P,--param", params, "Build parameter NAME=VALUE (repeatable; docs/KDTREE.md, docs/BIH.md)");
    threads_option = cmd.add_option("--threads", threads, "Worker and build threads (0: all cores)")->capture_default_str();
    if (with_device)
        cmd.add_option("--device", device, "Where rays are traced: cpu, or cuda (kd and bih on the GPU; docs/GPU.md)")
            ->check(CLI::IsMember({"cpu", "cuda"}))
            ->capture_default_str();
}

AccelConfig AccelOptions::config() const {
    check_threads(threads);
    // --accel is a kind or the library's whole configuration string (parse_accel_config); --traversal,
    // --simd and -P add to it and may not contradict it.
    AccelConfig c;
    try {
        c = parse_accel_config(kind);
    } catch (const Error& e) {
        throw Error("--accel '" + kind + "': " + e.what());
    }
    const auto contradiction = [&](const std::string& option) {
        return Error(option + " contradicts --accel '" + kind + "'");
    };
    if (!traversal.empty()) {
        if (!c.traversal.empty() && c.traversal != traversal) throw contradiction("--traversal '" + traversal + "'");
        c.traversal = traversal;
    }
    const bool simd_given = simd_option && simd_option->count() > 0;
    if (simd_named()) {
        if (simd_given && simd != c.simd) throw contradiction("--simd '" + simd + "'");
    } else {
        c.simd = (!c.traversal.empty() || device != "cpu") && !simd_given ? "off" : simd;
    }
    c.device = device;
    c.threads = threads;
    const AccelConfig named = c;  // what --accel set
    for (const std::string& p : params) {
        const auto eq = p.find('=');
        if (eq == std::string::npos || eq == 0) throw Error("--param '" + p + "' must have the form NAME=VALUE");
        const std::string name = p.substr(0, eq), value = p.substr(eq + 1);
        if (const auto it = c.params.find(name); it != c.params.end() && it->second != value) {
            if (named.params.count(name)) throw contradiction("--param '" + p + "'");
            throw Error("--param '" + p + "' contradicts --param '" + name + "=" + it->second + "'");
        }
        c.params[name] = value;
    }
    return c;
}

bool AccelOptions::describes_structure() const {
    for (const CLI::Option* o : {simd_option, traversal_option, params_option, threads_option})
        if (o && o->count() > 0) return true;
    return false;
}

bool AccelOptions::simd_named() const { return kind.substr(0, kind.find('@')).find('+') != std::string::npos; }

std::string AccelOptions::simd_source() const { return simd_named() ? "--accel '" + kind + "'" : "--simd"; }

CLI::Validator non_empty() {
    return CLI::Validator([](const std::string& s) { return s.empty() ? std::string("must not be empty") : std::string(); },
                          "", "NONEMPTY");
}

std::unique_ptr<Accelerator> build_structure(std::span<const Triangle> triangles, const AccelConfig& config,
                                             const AccelOptions& options) {
    // A SIMD set this binary or processor cannot run, named by the option that gave it.
    const auto check_simd = [&] {
        try {
            detail::parse_isa(config.simd);
        } catch (const Error& e) {
            throw Error(options.simd_source() + ": " + e.what());
        }
    };
    // A tree's single-ray kernel named with SIMD packets, which would replace it (the library refuses
    // it too): said in the options' words, once the SIMD set is known to be one.
    if (names_replaced_traversal(config)) {
        check_simd();
        const std::string kernel =
            options.traversal.empty() ? "--accel '" + options.kind + "'" : "--traversal '" + options.traversal + "'";
        if (kernel == options.simd_source())
            throw Error(kernel + " names a single-ray kernel ('" + config.traversal + "') and SIMD packets ('" +
                        config.simd + "'), which would replace it: leave one of them out");
        throw Error(kernel + " names a single-ray kernel, which the SIMD packets of " + options.simd_source() +
                    " replace: leave one of them out");
    }
    std::unique_ptr<Accelerator> accel;
    try {
        accel = make_accelerator(triangles, config);
    } catch (const Error&) {
        if (config.simd == "off") throw;
        check_simd();
        throw;
    }
    return accel;
}

AccelConfig check_names(const AccelOptions& options) {
    const AccelConfig config = options.config();
    // The library's words for an unknown kind, behind the option that gave it.
    const std::vector<std::string>* traversals = nullptr;
    try {
        traversals = &accelerator_traversals(config.kind);
    } catch (const Error& e) {
        throw Error("--accel '" + options.kind + "': " + e.what());
    }
    if (!config.traversal.empty() && std::find(traversals->begin(), traversals->end(), config.traversal) == traversals->end())
        throw Error((options.traversal.empty() ? "--accel '" + options.kind + "'" : "--traversal '" + options.traversal + "'") +
                    ": " + config.kind + " has no traversal '" + config.traversal + "' (it has: " +
                    detail::join_names(*traversals) + ")");
    return config;
}

void check_structure(const AccelOptions& options) {
    build_structure(std::span<const Triangle>(&kOneTriangle, 1), check_names(options), options);
}

void check_threads(unsigned threads) {
    if (threads > kMaxWorkers)
        throw Error("--threads " + std::to_string(threads) + " must lie in [0, " + std::to_string(kMaxWorkers) + "]");
}

void check_packet_fits(int packet, std::size_t budget_bytes, const std::string& remedy) {
    const std::size_t rays = static_cast<std::size_t>(packet) * static_cast<std::size_t>(packet);
    const std::size_t most = max_batch_rays(budget_bytes);
    if (rays <= most) return;
    std::size_t edge = 0;
    while ((edge + 1) * (edge + 1) <= most) ++edge;
    throw Error("--packet " + std::to_string(packet) + ": a packet's " + std::to_string(rays) +
                " rays and their results do not fit the local store's " + std::to_string(budget_bytes) +
                " bytes (a batch alone fits up to --packet " + std::to_string(edge) +
                ", and the caches and the stack need room besides" + remedy + ")");
}

std::string json_report(const nlohmann::json& report) {
    return report.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void print_stats(const AccelStats& s) {
    std::printf("structure        %s\n", s.name.c_str());
    std::printf("build time       %.3f s\n", s.build_seconds);
    std::printf("memory           %.2f MiB\n", static_cast<double>(s.memory_bytes) / (1024.0 * 1024.0));
    for (const auto& [k, v] : s.figures()) std::printf("%-16s %s\n", k.c_str(), v.c_str());
}

Progress::Progress() : enabled_(::isatty(STDERR_FILENO)) {}

Progress::~Progress() { finish(); }

void Progress::finish() {
    std::lock_guard lock(mutex_);
    if (shown_) std::fprintf(stderr, "\n");
    shown_ = false;
    enabled_ = false;
}

void Progress::operator()(std::size_t done, std::size_t total) {
    if (!enabled_ || timer_.seconds() < 1.0) return;
    std::lock_guard lock(mutex_);
    // The workers call at once and a later count may come first (found by audit, 2026-12-07): the bar
    // never goes back, and the frame's last call need not be its largest.
    if (done < drawn_) return;
    drawn_ = done;
    const int width = 40, filled = static_cast<int>(width * done / total);
    std::fprintf(stderr, "\r[%s%s] %3zu%%", std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(),
                 100 * done / total);
    shown_ = true;
}

}  // namespace cellrt::cli
