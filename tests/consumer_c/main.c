/* A C program of a library user: builds a kd-tree over one triangle and traces one ray at it. */
#include <stdio.h>

#include <cellrt/cellrt.h>

int main(void) {
    const float vertices[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint32_t indices[3] = {0, 1, 2};
    const cellrt_ray ray = {0.25f, 0.25f, 1.f, 0.f, 0.f, 0.f, -1.f, 1e30f};
    cellrt_hit hit;
    cellrt_device device = cellrt_device_new();
    cellrt_scene scene = cellrt_scene_new(device, vertices, 3, indices, 1);
    cellrt_accel accel = cellrt_accel_new(scene, "kd");
    const cellrt_error e = cellrt_intersect(accel, &ray, &hit, 1);
    printf("%s: hit triangle %u at t = %g\n", cellrt_error_name(e), hit.prim, hit.t);
    cellrt_accel_release(accel);
    cellrt_scene_release(scene);
    cellrt_device_release(device);
    return e == CELLRT_SUCCESS && hit.prim == 0 && hit.t == 1.f ? 0 : 1;
}
