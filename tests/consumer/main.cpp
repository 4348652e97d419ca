// A program of a library user: finds the installed package, builds a structure, traces one ray and
// writes a PNG (the image code needs stb's writer, which the package must bring: it once did not).
#include <cellrt/cellrt.hpp>

#include <cstdio>

int main(int argc, char** argv) {
    const cellrt::Scene scene = cellrt::make_builtin_scene("builtin:spheres?tris=1000");
    const auto accel = cellrt::make_accelerator(scene.triangles, {.kind = "kd"});
    cellrt::Ray ray;
    ray.org = scene.camera.position;
    ray.dir = scene.camera.look_at - scene.camera.position;
    cellrt::Hit hit;
    accel->intersect(std::span(&ray, 1), std::span(&hit, 1));
    std::printf("cellrt %s: hit triangle %u at t = %g\n", CELLRT_VERSION_STRING, hit.prim, hit.t);
    if (!hit.is_hit()) return 1;
    cellrt::Image image(2, 2);
    cellrt::write_image(image, argc > 1 ? argv[1] : "consumer.png", true);
    return 0;
}
