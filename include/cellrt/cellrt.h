/* The C API of cellrt (C99; docs/C_API.md): devices, scenes and accelerators behind opaque handles,
 * error codes with a per-device error callback, and closest-hit and any-hit queries over arrays of
 * rays, as an array of structs or as separate arrays. Its shape follows Embree's rtcore API.
 *
 * Handles. A handle is an opaque number, never reused within a process: a released or made-up handle,
 * or a handle of another kind, is refused with CELLRT_ERROR_INVALID_HANDLE rather than read. Each
 * handle has a reference count, 1 when made; retain adds one, release takes one, and the handle dies at
 * zero. A scene keeps its device and an accelerator keeps its scene alive internally, so handles may be
 * released in any order.
 *
 * Errors. Every function that can fail returns a cellrt_error (or NULL for a handle) and records the
 * error for the calling thread on the device concerned, then calls the device's error function if one
 * is set. An error with no device to go to (a NULL or invalid device, scene or accelerator handle,
 * and every refused retain or release) is recorded for the calling thread under the NULL device and
 * calls no error function. No C++ exception leaves any function.
 *
 * Thread safety. Every function may be called from any number of threads at once. intersect and
 * occluded calls may run at once on one accelerator and each gets the answers it gets alone; they must
 * not write overlapping result arrays. A handle released while another thread's call is using it stays
 * alive until that call returns. Error records are per thread, and end with their thread; the error
 * function may be called from several threads at once and must be safe for that.
 *
 * Lifetimes. Input arrays are read only during the call that takes them (a scene copies its vertices
 * and indices). Results are written only by the call, before it returns. */
#ifndef CELLRT_CELLRT_H
#define CELLRT_CELLRT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define CELLRT_API __attribute__((visibility("default")))
#else
#define CELLRT_API
#endif

/* The version of this API; changes when a declaration below changes. */
#define CELLRT_C_API_VERSION 3

/* prim of a ray that hits nothing. */
#define CELLRT_INVALID_ID UINT32_MAX

typedef enum cellrt_error {
    CELLRT_SUCCESS = 0,
    CELLRT_ERROR_UNKNOWN = 1,          /* an internal error; the message says what */
    CELLRT_ERROR_INVALID_ARGUMENT = 2, /* a NULL array, a bad count, an index out of range, a NaN */
    CELLRT_ERROR_INVALID_HANDLE = 3,   /* NULL, released, or not a handle of the expected kind */
    CELLRT_ERROR_INVALID_CONFIG = 4,   /* the accelerator configuration string */
    CELLRT_ERROR_OUT_OF_MEMORY = 5,
    CELLRT_ERROR_IO = 6                /* a scene file that cannot be read or is malformed */
} cellrt_error;

typedef struct cellrt_device_handle* cellrt_device;
typedef struct cellrt_scene_handle* cellrt_scene;
typedef struct cellrt_accel_handle* cellrt_accel;

/* Called on the failing thread before the failing function returns; `message` is one line naming
 * the argument at fault and is valid during the call only. */
typedef void (*cellrt_error_function)(void* user, cellrt_error code, const char* message);

/* A ray as one struct: origin, tnear, direction, tfar (32 bytes). Under the hit rule a hit has
 * tnear <= t <= tfar; a ray with a non-finite or zero direction (or one whose components are all
 * subnormal), a non-finite origin, a NaN bound, tnear > tfar or tnear = +inf hits nothing
 * (docs/HIT_SEMANTICS.md). */
typedef struct cellrt_ray {
    float org_x, org_y, org_z, tnear;
    float dir_x, dir_y, dir_z, tfar;
} cellrt_ray;

/* A closest hit: t, the triangle's index in its scene, and the barycentrics (the point is
 * (1-u-v)*v0 + u*v1 + v*v2). A miss has t = INFINITY, prim = CELLRT_INVALID_ID, u = v = 0. */
typedef struct cellrt_hit {
    float t;
    uint32_t prim;
    float u, v;
} cellrt_hit;

/* Rays as separate arrays (structure of arrays), each of the call's count; tnear and tfar may be NULL
 * for 0 and INFINITY. */
typedef struct cellrt_rays_soa {
    const float *org_x, *org_y, *org_z;
    const float *dir_x, *dir_y, *dir_z;
    const float *tnear, *tfar;
} cellrt_rays_soa;

/* Hits as separate arrays; u and v may be NULL when not wanted. */
typedef struct cellrt_hits_soa {
    float* t;
    uint32_t* prim;
    float *u, *v;
} cellrt_hits_soa;

/* Devices. */
CELLRT_API cellrt_device cellrt_device_new(void);
CELLRT_API cellrt_error cellrt_device_retain(cellrt_device device);
CELLRT_API cellrt_error cellrt_device_release(cellrt_device device);
CELLRT_API cellrt_error cellrt_device_set_error_function(cellrt_device device, cellrt_error_function function,
                                                        void* user);
/* The calling thread's latest error on `device` (NULL: errors that had no device), then reset to
 * CELLRT_SUCCESS. When `message` is not NULL it receives that error's message ("" for none), valid
 * until the calling thread's next error on the device, until the device is released (its records
 * are then dropped as the thread records other errors) or until the thread ends, whichever comes
 * first: copy it to keep it. */
CELLRT_API cellrt_error cellrt_device_get_error(cellrt_device device, const char** message);

/* Scenes: triangles from float32 xyz vertices (3 * vertex_count floats) and uint32 indices
 * (3 * triangle_count, each below vertex_count). Every vertex must be finite. */
CELLRT_API cellrt_scene cellrt_scene_new(cellrt_device device, const float* vertices, size_t vertex_count,
                                         const uint32_t* indices, size_t triangle_count);
/* A scene file read by cellrt's loader: a view file (.json), OBJ, PLY, glTF (.gltf, .glb), or
 * "builtin:NAME[?key=value&...]". */
CELLRT_API cellrt_scene cellrt_scene_load(cellrt_device device, const char* path);
CELLRT_API cellrt_error cellrt_scene_retain(cellrt_scene scene);
CELLRT_API cellrt_error cellrt_scene_release(cellrt_scene scene);
/* The triangle count and the bounding box (lo and hi of 3 floats each; lo > hi for no triangles). */
CELLRT_API cellrt_error cellrt_scene_get_info(cellrt_scene scene, size_t* triangle_count, float lo[3], float hi[3]);

/* Accelerators: a structure built over `scene` from a configuration string
 * KIND[:TRAVERSAL][+SIMD][@NAME=VALUE,...], e.g. "kd", "bih:branchless", "kd+auto@leaf_size=2", "brute";
 * NULL is the library's default, "auto@packets=bvh" (one wide BVH, each batch on its fastest traversal;
 * "kd" on "cuda" below). Its kinds, traversals and parameters are those `cellrt info --params KIND`
 * lists. */
CELLRT_API cellrt_accel cellrt_accel_new(cellrt_scene scene, const char* config);
/* The same, traced where `where` says: "cpu" (or NULL), as cellrt_accel_new; "cuda": the tree built on
 * the host and traced on the GPU, one ray per GPU thread (kinds kd and bih, no SIMD set; docs/GPU.md).
 * An unknown place, or "cuda" where there is no GPU or no CUDA in this build, is INVALID_CONFIG with
 * the reason. Since version 2. */
CELLRT_API cellrt_accel cellrt_accel_new_on(cellrt_scene scene, const char* config, const char* where);
CELLRT_API cellrt_error cellrt_accel_retain(cellrt_accel accel);
CELLRT_API cellrt_error cellrt_accel_release(cellrt_accel accel);
/* What `accel` is: the configuration it was built from, in full ("auto@packets=bvh" for NULL on the
 * CPU; parameters sorted by name), where it traces ("cpu" or "cuda"), both valid while the
 * accelerator lives; the build's wall time in seconds and the bytes its structure holds. Each output
 * may be NULL. Since version 3. */
CELLRT_API cellrt_error cellrt_accel_get_info(cellrt_accel accel, const char** config, const char** where,
                                              double* build_seconds, size_t* memory_bytes);

/* Closest hits of `count` rays; arrays may be NULL when count is 0. */
CELLRT_API cellrt_error cellrt_intersect(cellrt_accel accel, const cellrt_ray* rays, cellrt_hit* hits, size_t count);
CELLRT_API cellrt_error cellrt_intersect_soa(cellrt_accel accel, const cellrt_rays_soa* rays,
                                             const cellrt_hits_soa* hits, size_t count);
/* Any hit: occluded[i] = 1 when some triangle is hit with tnear <= t <= tfar, else 0. */
CELLRT_API cellrt_error cellrt_occluded(cellrt_accel accel, const cellrt_ray* rays, uint8_t* occluded, size_t count);
CELLRT_API cellrt_error cellrt_occluded_soa(cellrt_accel accel, const cellrt_rays_soa* rays, uint8_t* occluded,
                                            size_t count);

/* The name of an error code ("CELLRT_ERROR_INVALID_ARGUMENT"); never NULL. */
CELLRT_API const char* cellrt_error_name(cellrt_error code);

#ifdef __cplusplus
}
#endif

#endif /* CELLRT_CELLRT_H */
