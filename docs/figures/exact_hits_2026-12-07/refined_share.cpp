// The share of a scene's camera-ray hits (512 x 512, the view file's camera, the kd-tree) whose ratio
// lateral * depth / |det| (triangle.hpp, ill_conditioned) passes 16, 64 and 256; and, on a second
// line, the share a ray-free bound would have sent on to that ratio, tried and not kept
// (HIT_SEMANTICS.md, "What the exactness costs"): E^2 / |det| (E the triangle's largest extent along
// an axis) above 16 and 32, and E times its extent along the ray's dominant axis above 32. A hit
// over 64 that the bound E^2 / 16 would have missed is printed.
//   g++ -O2 -std=c++20 -ffp-contract=off -Iinclude docs/figures/exact_hits_2026-12-07/refined_share.cpp build/libcellrt.a \
//       -ltbb -lstb -lembree3 /usr/local/cuda/lib/libcudart_static.a -ldl -lrt -lpthread -o /tmp/r && /tmp/r SCENE.json...
#include <cellrt/cellrt.hpp>
#include <algorithm>
#include <cstdio>
using namespace cellrt;
int main(int argc, char** argv) {
    for (int a = 1; a < argc; ++a) {
        const Scene scene = load_scene(argv[a]);
        const PinholeCamera cam(scene.camera, 512, 512);
        std::vector<Ray> rays;
        for (int y = 0; y < 512; ++y) for (int x = 0; x < 512; ++x) rays.push_back(cam.primary(x, y));
        auto acc = make_accelerator(scene.triangles, AccelConfig{"kd"});
        std::vector<Hit> hits(rays.size());
        acc->intersect(rays, hits);
        std::size_t n = 0, ill = 0, ill64 = 0, ill256 = 0, e16 = 0, e32 = 0, ek32 = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if (!hits[i].is_hit()) continue;
            ++n;
            const WatertightRay w(rays[i]);
            const float* c9 = reinterpret_cast<const float*>(&scene.triangles[hits[i].prim]);
            float x[3], y[3], z[3];
            for (int q = 0; q < 3; ++q) {
                z[q] = c9[3 * q + w.kz] - w.org[w.kz];
                x[q] = (c9[3 * q + w.kx] - w.org[w.kx]) - w.sx * z[q];
                y[q] = (c9[3 * q + w.ky] - w.org[w.ky]) - w.sy * z[q];
            }
            float lat = 0; for (int q = 0; q < 3; ++q) lat = std::max({lat, std::fabs(x[q]), std::fabs(y[q])});
            const float depth = std::max({z[0], z[1], z[2]}) - std::min({z[0], z[1], z[2]});
            const float det = (x[2] * y[1] - y[2] * x[1]) + (x[0] * y[2] - y[0] * x[2]) + (x[1] * y[0] - y[1] * x[0]);
            auto extent = [&](int k) {
                return std::max({c9[k], c9[3 + k], c9[6 + k]}) - std::min({c9[k], c9[3 + k], c9[6 + k]});
            };
            const float e = std::max({extent(0), extent(1), extent(2)});
            const double r = (double)lat * depth / std::fabs(det), re = (double)e * e / std::fabs(det),
                         rk = (double)e * extent(w.kz) / std::fabs(det);
            ill += r > 16; ill64 += r > 64; ill256 += r > 256;
            e16 += re > 16; e32 += re > 32; ek32 += rk > 32;
            if (r > 64 && !(re > 16)) std::printf("a hit over 64 the bound misses: ratio %g, E^2/|det| %g\n", r, re);
        }
        std::printf("%s: %zu hits, >16 %.3f %%, >64 %.3f %%, >256 %.3f %%\n", scene.name.c_str(), n, 100.0 * ill / n, 100.0 * ill64 / n, 100.0 * ill256 / n);
        std::printf("%s: the ray-free bound: E^2 >16 %.3f %%, E^2 >32 %.3f %%, E * E_kz >32 %.3f %%\n", scene.name.c_str(),
                    100.0 * e16 / n, 100.0 * e32 / n, 100.0 * ek32 / n);
    }
}
