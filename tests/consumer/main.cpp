// A program of a library user: finds the installed package, builds a structure, traces one ray.
#include <cellrt/cellrt.hpp>

#include <cstdio>

int main() {
    const cellrt::Scene scene = cellrt::make_builtin_scene("builtin:spheres?tris=1000");
    const auto accel = cellrt::make_accelerator(scene.triangles, {.kind = "kd"});
    cellrt::Ray ray;
    ray.org = scene.camera.position;
    ray.dir = scene.camera.look_at - scene.camera.position;
    cellrt::Hit hit;
    accel->intersect(std::span(&ray, 1), std::span(&hit, 1));
    std::printf("cellrt %s: hit triangle %u at t = %g\n", CELLRT_VERSION_STRING, hit.prim, hit.t);
    return hit.is_hit() ? 0 : 1;
}
