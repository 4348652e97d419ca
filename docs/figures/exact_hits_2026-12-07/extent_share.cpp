// The share of camera-ray hits (512 x 512, the kd-tree) that a ray-free bound would send to the
// lateral ratio: E^2 / |det| (E the triangle's largest extent) above 16 and 32, and E times its extent
// along the ray's dominant axis above 32; tried as a first half of the ill-conditioning rule, not kept
// (HIT_SEMANTICS.md, "What the exactness costs"). Built as refined_share.cpp.
#include <cellrt/cellrt.hpp>
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
        std::size_t n = 0, old64 = 0, e16 = 0, e32 = 0, ek16 = 0;
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
            float E = 0;
            for (int k = 0; k < 3; ++k) E = std::max(E, std::max({c9[k], c9[3 + k], c9[6 + k]}) - std::min({c9[k], c9[3 + k], c9[6 + k]}));
            const float Ek = std::max({c9[w.kz], c9[3 + w.kz], c9[6 + w.kz]}) - std::min({c9[w.kz], c9[3 + w.kz], c9[6 + w.kz]});
            const double r = (double)lat * depth / std::fabs(det), re = (double)E * E / std::fabs(det), rk = (double)E * Ek / std::fabs(det);
            old64 += r > 64; e16 += re > 16; e32 += re > 32; ek16 += rk > 32;
            if (r > 64 && !(re > 32)) std::printf("NOT CONSERVATIVE %g %g\n", r, re);
        }
        std::printf("%s: %zu hits, old>64 %.3f %%, E2>16 %.3f %%, E2>32 %.3f %%, E*Ekz>32 %.3f %%\n", scene.name.c_str(), n, 100.0 * old64 / n, 100.0 * e16 / n, 100.0 * e32 / n, 100.0*ek16/n);
    }
}
