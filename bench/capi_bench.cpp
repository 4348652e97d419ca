// The C API's cost over the C++ interface (docs/C_API.md): the same primary rays of a scene traced by
// Accelerator::intersect and by cellrt_intersect over the same structure, interleaved, medians of
// seven runs each; the hits must be equal. Usage: cellrt_capi_bench [SCENE [CONFIG...]].
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/cellrt.h"
#include "cellrt/scene.hpp"

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

template <class F>
double seconds(F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

constexpr const char* kUsage = "usage: cellrt_capi_bench [SCENE [CONFIG...]]   (default: builtin:city kd+auto bvh)";

int run(int argc, char** argv) {
    const std::string spec = argc > 1 ? argv[1] : "builtin:city";
    std::vector<std::string> configs(argv + std::min(argc, 2), argv + argc);
    if (configs.empty()) configs = {"kd+auto", "bvh"};
    const cellrt::Scene scene = cellrt::load_scene(spec);
    const cellrt::PinholeCamera camera(scene.camera, 1024, 1024);
    std::vector<cellrt::Ray> rays;
    std::vector<cellrt_ray> c_rays;
    for (int y = 0; y < 1024; ++y)
        for (int x = 0; x < 1024; ++x) {
            const cellrt::Ray r = camera.primary(x, y);
            rays.push_back(r);
            c_rays.push_back({r.org.x, r.org.y, r.org.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, r.tfar});
        }
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
    for (const cellrt::Triangle& t : scene.triangles)
        for (const cellrt::Vec3& p : {t.v0, t.v1, t.v2}) {
            vertices.insert(vertices.end(), {p.x, p.y, p.z});
            indices.push_back(static_cast<std::uint32_t>(indices.size()));
        }
    cellrt_device device = cellrt_device_new();
    cellrt_scene c_scene = cellrt_scene_new(device, vertices.data(), vertices.size() / 3, indices.data(),
                                            scene.triangles.size());
    int status = 0;
    for (const std::string& config : configs) {
        const auto accel = cellrt::make_accelerator(scene.triangles, cellrt::parse_accel_config(config));
        cellrt_accel c_accel = cellrt_accel_new(c_scene, config.c_str());
        std::vector<cellrt::Hit> hits(rays.size());
        std::vector<cellrt_hit> c_hits(rays.size());
        std::vector<double> cpp, c;
        for (int run = 0; run < 7; ++run) {
            cpp.push_back(seconds([&] { accel->intersect(rays, hits); }));
            c.push_back(seconds([&] { cellrt_intersect(c_accel, c_rays.data(), c_hits.data(), c_rays.size()); }));
        }
        std::size_t equal = 0;
        for (std::size_t i = 0; i < rays.size(); ++i)
            equal += hits[i].prim == c_hits[i].prim &&
                     (!hits[i].is_hit() || std::memcmp(&hits[i].t, &c_hits[i].t, sizeof(float)) == 0);
        const double n = static_cast<double>(rays.size());
        std::printf("%s %s: %zu rays; C++ %.3f s (%.2f Mrays/s), C API %.3f s (%.2f Mrays/s), C/C++ %.3f; equal %zu\n",
                    spec.c_str(), config.c_str(), rays.size(), median(cpp), n / median(cpp) / 1e6, median(c),
                    n / median(c) / 1e6, median(c) / median(cpp), equal);
        if (equal != rays.size()) status = 1;
        cellrt_accel_release(c_accel);
    }
    cellrt_scene_release(c_scene);
    cellrt_device_release(device);
    return status;
}

}  // namespace

// A bad scene or configuration is one line and status 1, as in the other programs (it ended in
// std::terminate: found by review, 2026-12-07).
int main(int argc, char** argv) {
    if (argc > 1 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
        std::puts(kUsage);
        return 0;
    }
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "cellrt_capi_bench: error: %s\n%s\n", e.what(), kUsage);
        return 1;
    }
}
