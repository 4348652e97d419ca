// The camera rays at 256 x 256 that hit, traced N times by one configuration, for `perf record`:
//   g++ -O2 -g -std=c++20 -Iinclude docs/figures/kd_single_round23/loop_hits.cpp -o /tmp/loop_hits \
//       build/libcellrt.a -ltbb -lstb -lembree3 /usr/local/cuda/lib/libcudart_static.a -ldl -lrt -lpthread
//   perf record -e cpu-clock -o /tmp/perf.data /tmp/loop_hits ../shared/scenes/bunny/bunny.json kd branched 300
//   perf annotate -i /tmp/perf.data --stdio -s '<the kernel's symbol>'
#include <cstdlib>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/scene.hpp"

using namespace cellrt;

int main(int argc, char** argv) {
    const Scene s = load_scene(argv[1]);
    const int side = 256;
    const PinholeCamera cam(s.camera, side, side);
    std::vector<Ray> rays;
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) rays.push_back(cam.primary(x, y));
    AccelConfig config;
    config.kind = argv[2];
    config.traversal = argv[3];
    config.threads = 1;
    const auto accel = make_accelerator(s.triangles, config);
    std::vector<Hit> hits(rays.size());
    accel->intersect(rays, hits);
    std::vector<Ray> hit_rays;
    for (std::size_t i = 0; i < rays.size(); ++i)
        if (hits[i].is_hit()) hit_rays.push_back(rays[i]);
    std::vector<Hit> out(hit_rays.size());
    for (int rep = 0; rep < std::atoi(argv[4]); ++rep) accel->intersect(hit_rays, out);
}
