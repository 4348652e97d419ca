// The study's scaling measurement (its Tables 5-1 and 5-2), with Embree alongside: seconds per frame
// (primary + one shadow ray per hit) for 1..N workers, per scene, structure, dispatch mode and packet
// size. Warm-up frame, then the median of --repeats frames. Writes a Markdown table to stdout and
// every measurement as CSV and JSON; bench/plot_scaling.py draws the curves.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "cellrt/accel.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/timer.hpp"

namespace {

using namespace cellrt;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

AccelConfig parse_config(const std::string& text) {
    AccelConfig c;
    const auto colon = text.find(':');
    c.kind = text.substr(0, colon);
    if (colon != std::string::npos) c.traversal = text.substr(colon + 1);
    c.threads = 1;
    return c;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"cellrt scaling study: seconds per frame vs workers, dispatch and packet size"};
    std::string scenes_dir = "../shared/scenes";
    std::vector<std::string> scenes{"sponza", "sibenik", "bunny", "teapot", "builtin:city", "builtin:forest"};
    std::vector<std::string> configs{"embree", "kd", "bih"};  // embree first: the others are compared with it
    std::vector<std::string> dispatches{"pull", "mailbox"};
    std::vector<int> packets{2, 16};
    std::vector<unsigned> workers;
    int repeats = 3, size = 512;
    std::string csv_path, json_path;
    app.add_option("--scenes-dir", scenes_dir, "Folder of the shared scenes")->capture_default_str();
    app.add_option("--scenes", scenes, "Shared scene names or builtin:... specs")->capture_default_str();
    app.add_option("--configs", configs, "Structures KIND[:TRAVERSAL]")->capture_default_str();
    app.add_option("--dispatch", dispatches, "Dispatch modes")->capture_default_str();
    app.add_option("--packets", packets, "Packet edges P (P x P rays)")->capture_default_str();
    app.add_option("--workers", workers, "Worker counts (default 1..cores)");
    app.add_option("--repeats", repeats, "Timed frames per point (median)")->capture_default_str();
    app.add_option("--size", size, "Image edge (square, as in the study)")->capture_default_str();
    app.add_option("--csv", csv_path, "Write every point as CSV");
    app.add_option("--json", json_path, "Write every point as JSON");
    CLI11_PARSE(app, argc, argv);
    if (workers.empty())
        for (unsigned w = 1; w <= std::max(1u, std::thread::hardware_concurrency()); ++w) workers.push_back(w);

    nlohmann::json points = nlohmann::json::array();
    try {
        for (const std::string& name : scenes) {
            std::string spec = name;
            if (name.rfind("builtin:", 0) != 0) {
                spec = (std::filesystem::path(scenes_dir) / name / (name + ".json")).string();
                if (!std::filesystem::exists(spec)) {
                    std::fprintf(stderr, "skipping %s: %s not found\n", name.c_str(), spec.c_str());
                    continue;
                }
            }
            const Scene scene = load_scene(spec);
            std::map<std::string, double> embree_seconds;  // key: dispatch/packet/workers
            for (const std::string& cfg_text : configs) {
                const AccelConfig cfg = parse_config(cfg_text);
                const auto kinds = accelerator_kinds();
                if (std::find(kinds.begin(), kinds.end(), cfg.kind) == kinds.end()) {
                    std::fprintf(stderr, "skipping %s: not built into this binary\n", cfg.kind.c_str());
                    continue;
                }
                const auto accel = make_accelerator(scene.triangles, cfg);
                std::printf("\n### %s, %s\n\n| dispatch | packet |", scene.name.c_str(), cfg_text.c_str());
                for (unsigned w : workers) std::printf(" %u |", w);
                std::printf(" efficiency at %u |\n|---|---|", workers.back());
                for (std::size_t i = 0; i <= workers.size(); ++i) std::printf("---|");
                std::printf("\n");
                for (const std::string& d : dispatches)
                    for (int p : packets) {
                        std::printf("| %s | %dx%d |", d.c_str(), p, p);
                        double t1 = 0.0, tn = 0.0;
                        for (unsigned w : workers) {
                            RenderOptions o;
                            o.width = o.height = size;
                            o.threads = w;
                            o.packet = p;
                            o.dispatch = parse_dispatch(d);
                            render(scene, *accel, o);  // warm-up
                            std::vector<double> times;
                            for (int r = 0; r < repeats; ++r) {
                                RenderStats st;
                                render(scene, *accel, o, &st);
                                times.push_back(st.seconds);
                            }
                            const double t = median(times);
                            if (w == workers.front()) t1 = t * workers.front();
                            tn = t;
                            const std::string key = d + "/" + std::to_string(p) + "/" + std::to_string(w);
                            if (cfg.kind == "embree") embree_seconds[key] = t;
                            nlohmann::json pt{{"scene", scene.name}, {"config", cfg_text}, {"dispatch", d},
                                              {"packet", p},         {"workers", w},       {"seconds", t}};
                            if (embree_seconds.count(key)) pt["embree_seconds"] = embree_seconds[key];
                            points.push_back(pt);
                            std::printf(" %.4f |", t);
                            std::fflush(stdout);
                        }
                        std::printf(" %.2f |\n", t1 / (tn * workers.back()));
                    }
            }
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "cellrt_scaling: error: %s\n", e.what());
        return 1;
    }
    if (!json_path.empty()) std::ofstream(json_path) << points.dump(1) << "\n";
    if (!csv_path.empty()) {
        std::ofstream csv(csv_path);
        csv << "scene,config,dispatch,packet,workers,seconds\n";
        for (const auto& p : points)
            csv << p["scene"].get<std::string>() << ',' << p["config"].get<std::string>() << ','
                << p["dispatch"].get<std::string>() << ',' << p["packet"] << ',' << p["workers"] << ',' << p["seconds"]
                << '\n';
    }
    return 0;
}
