// Camera rays of a scene at 256 x 256 sorted into three kinds (miss the scene box, cross it without a
// hit, hit), and each kind traced alone by `kd:branched` and by Embree's rtcIntersect1 (`embree:single`),
// best of 15 batches each, the two in turn; "hit x4" traces every hit ray four times in a row, so that
// three of the four find its path predicted and its nodes and triangles in cache. With a second
// argument the triangles are first sorted by the Morton code of their centres.
//
// Built against the library (from the repository root, after the README's build):
//   g++ -O2 -std=c++20 -Iinclude docs/figures/kd_single_round23/class_time.cpp -o /tmp/class_time \
//       build/libcellrt.a -ltbb -lstb -lembree3 /usr/local/cuda/lib/libcudart_static.a -ldl -lrt -lpthread
//   /tmp/class_time ../shared/scenes/bunny/bunny.json [morton]
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/scene.hpp"

using namespace cellrt;

static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static std::uint64_t morton(const Triangle& t, const Box3& box) {
    const Vec3 c = (t.v0 + t.v1 + t.v2) * (1.f / 3.f);
    std::uint32_t q[3];
    for (int a = 0; a < 3; ++a)
        q[a] = static_cast<std::uint32_t>(
            std::clamp((c[a] - box.lo[a]) / (box.hi[a] - box.lo[a]) * 1024.f, 0.f, 1023.f));
    std::uint64_t k = 0;
    for (int bit = 9; bit >= 0; --bit)
        for (int a = 0; a < 3; ++a) k = (k << 1) | ((q[a] >> bit) & 1u);
    return k;
}

int main(int argc, char** argv) {
    Scene s = load_scene(argv[1]);
    const Box3 box = s.bounds();
    if (argc > 2)
        std::stable_sort(s.triangles.begin(), s.triangles.end(),
                         [&](const Triangle& a, const Triangle& b) { return morton(a, box) < morton(b, box); });
    const int side = 256;
    const PinholeCamera cam(s.camera, side, side);
    std::vector<Ray> rays;
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) rays.push_back(cam.primary(x, y));
    AccelConfig kd_config, embree_config;
    kd_config.kind = "kd";
    kd_config.traversal = "branched";
    embree_config.kind = "embree";
    embree_config.traversal = "single";
    kd_config.threads = embree_config.threads = 1;
    const auto kd = make_accelerator(s.triangles, kd_config);
    const auto embree = make_accelerator(s.triangles, embree_config);
    std::vector<Hit> hits(rays.size());
    embree->intersect(rays, hits);

    std::vector<Ray> kinds[4];
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Ray& r = rays[i];
        float t0 = 0.f, t1 = 1e30f;
        for (int a = 0; a < 3; ++a) {
            const float inv = 1.f / r.dir[a];
            const float ta = (box.lo[a] - r.org[a]) * inv, tb = (box.hi[a] - r.org[a]) * inv;
            t0 = std::max(t0, std::min(ta, tb));
            t1 = std::min(t1, std::max(ta, tb));
        }
        kinds[hits[i].is_hit() ? 2 : (t0 <= t1 ? 1 : 0)].push_back(r);
    }
    for (const Ray& r : kinds[2])
        for (int k = 0; k < 4; ++k) kinds[3].push_back(r);

    const char* names[4] = {"miss box", "cross no hit", "hit", "hit x4"};
    for (int c = 0; c < 4; ++c) {
        if (kinds[c].empty()) continue;
        std::vector<Hit> out(kinds[c].size());
        TraversalCounters work;
        kd->intersect(kinds[c], out, &work);
        double best[2] = {1e9, 1e9};
        for (int rep = 0; rep < 15; ++rep)
            for (int k = 0; k < 2; ++k) {
                const double t = now();
                (k ? embree : kd)->intersect(kinds[c], out);
                best[k] = std::min(best[k], now() - t);
            }
        const double n = static_cast<double>(kinds[c].size());
        std::printf("%-13s %6zu rays  kd %6.1f ns/ray (nodes %4.1f leaves %4.1f triangles %4.1f)  embree %6.1f ns/ray  "
                    "embree/kd %.2f\n",
                    names[c], kinds[c].size(), best[0] / n * 1e9, work.nodes / n, work.leaves / n, work.triangles / n,
                    best[1] / n * 1e9, best[1] / best[0]);
    }
}
