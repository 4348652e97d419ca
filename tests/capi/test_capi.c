/* The C API's test program, compiled as C99 (tests/CMakeLists.txt). One part per run, named by the
 * first argument: "hits" (every structure against brute force, both ray layouts, on built and loaded
 * scenes), "shared" (a scene of ../shared/scenes; exit 77, skipped, when absent), "errors" (every
 * error path), "threads" (concurrent queries on one accelerator, per-thread error records) and "exit"
 * (handles released by an atexit handler). */
#define _POSIX_C_SOURCE 200809L
#include <unistd.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cellrt/cellrt.h>

static int failures = 0;

#define CHECK(cond)                                                               \
    do {                                                                          \
        if (!(cond)) {                                                            \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
            ++failures;                                                           \
        }                                                                         \
    } while (0)

/* The calling thread's latest error on `device` has `code` and a message containing `part`. */
#define CHECK_ERROR(device, code, part) check_error(device, code, part, __FILE__, __LINE__)

static void check_error(cellrt_device device, cellrt_error code, const char* part, const char* file, int line) {
    const char* message = NULL;
    const cellrt_error got = cellrt_device_get_error(device, &message);
    if (got != code || message == NULL || strstr(message, part) == NULL) {
        fprintf(stderr, "%s:%d: expected %s containing '%s', got %s: '%s'\n", file, line, cellrt_error_name(code),
                part, cellrt_error_name(got), message ? message : "(null)");
        ++failures;
    }
    /* Reading resets the code; the message read again is "" (the text read before stays valid). */
    const char* again = NULL;
    CHECK(cellrt_device_get_error(device, &again) == CELLRT_SUCCESS && again && strcmp(again, "") == 0);
    CHECK(message && strstr(message, part) != NULL);
}

/* A deterministic generator (64-bit LCG), so that every run traces the same rays. */
static unsigned long long rng_state = 0x9e3779b97f4a7c15ULL;
static float uniform(float lo, float hi) {
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (float)((rng_state >> 40) & 0xffffff) / 16777216.0f;
}

/* Rays from around a box of the scene towards points inside it, with a few bounded ones. */
static void make_rays(cellrt_scene scene, cellrt_ray* rays, size_t n) {
    float lo[3], hi[3];
    size_t i;
    int a;
    CHECK(cellrt_scene_get_info(scene, NULL, lo, hi) == CELLRT_SUCCESS);
    if (lo[0] > hi[0])
        for (a = 0; a < 3; ++a) lo[a] = -1.f, hi[a] = 1.f;
    for (i = 0; i < n; ++i) {
        float o[3], t[3];
        for (a = 0; a < 3; ++a) {
            const float e = hi[a] - lo[a];
            o[a] = uniform(lo[a] - 0.5f * e, hi[a] + 0.5f * e);
            t[a] = uniform(lo[a], hi[a]);
        }
        rays[i].org_x = o[0], rays[i].org_y = o[1], rays[i].org_z = o[2];
        rays[i].dir_x = t[0] - o[0], rays[i].dir_y = t[1] - o[1], rays[i].dir_z = t[2] - o[2];
        rays[i].tnear = i % 7 == 3 ? 0.5f : 0.f;
        rays[i].tfar = i % 5 == 2 ? 0.8f : INFINITY;
    }
}

static int same_float(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

static int same_hit(const cellrt_hit* a, const cellrt_hit* b) {
    return a->prim == b->prim && same_float(a->t, b->t) && same_float(a->u, b->u) && same_float(a->v, b->v);
}

/* Brute force's answers for a set of rays, which every structure must give bit for bit. */
struct Reference {
    size_t n;
    cellrt_ray* rays;
    cellrt_hit *hits, *unbounded; /* unbounded: the same rays with tnear 0 and tfar INFINITY */
    uint8_t* occluded;
    long hit_count;
};

static struct Reference make_reference(cellrt_scene scene, size_t n) {
    struct Reference r;
    cellrt_accel brute = cellrt_accel_new(scene, "brute");
    cellrt_ray* open = malloc(n * sizeof *open);
    size_t i;
    r.n = n, r.rays = malloc(n * sizeof *r.rays), r.hits = malloc(n * sizeof *r.hits);
    r.unbounded = malloc(n * sizeof *r.unbounded), r.occluded = malloc(n), r.hit_count = 0;
    make_rays(scene, r.rays, n);
    CHECK(brute != NULL);
    CHECK(cellrt_intersect(brute, r.rays, r.hits, n) == CELLRT_SUCCESS);
    CHECK(cellrt_occluded(brute, r.rays, r.occluded, n) == CELLRT_SUCCESS);
    for (i = 0; i < n; ++i) open[i] = r.rays[i], open[i].tnear = 0.f, open[i].tfar = INFINITY;
    CHECK(cellrt_intersect(brute, open, r.unbounded, n) == CELLRT_SUCCESS);
    for (i = 0; i < n; ++i) {
        if (r.hits[i].prim == CELLRT_INVALID_ID) CHECK(isinf(r.hits[i].t) && r.hits[i].u == 0.f && r.hits[i].v == 0.f);
        else ++r.hit_count;
        CHECK(r.occluded[i] == (r.hits[i].prim != CELLRT_INVALID_ID));
    }
    CHECK(cellrt_accel_release(brute) == CELLRT_SUCCESS);
    free(open);
    return r;
}

static void free_reference(struct Reference* r) { free(r->rays), free(r->hits), free(r->unbounded), free(r->occluded); }

/* Traces the reference's rays through `config` in both layouts and compares with brute force bit for
 * bit; returns the number of rays that differ. */
static long compare_with_brute(cellrt_scene scene, const char* config, const struct Reference* ref) {
    const size_t n = ref->n;
    cellrt_accel accel = cellrt_accel_new(scene, config);
    cellrt_hit* got = malloc(n * sizeof *got);
    uint8_t *got_occ = malloc(n), *soa_occ = malloc(n);
    float* cols = malloc(11 * n * sizeof *cols);
    uint32_t* soa_prim = malloc(n * sizeof *soa_prim);
    cellrt_rays_soa soa;
    cellrt_hits_soa soa_hits;
    long mismatches = 0;
    size_t i;
    CHECK(accel != NULL);
    CHECK(cellrt_intersect(accel, ref->rays, got, n) == CELLRT_SUCCESS);
    CHECK(cellrt_occluded(accel, ref->rays, got_occ, n) == CELLRT_SUCCESS);
    for (i = 0; i < n; ++i) {
        const cellrt_ray* r = &ref->rays[i];
        cols[i] = r->org_x, cols[n + i] = r->org_y, cols[2 * n + i] = r->org_z;
        cols[3 * n + i] = r->dir_x, cols[4 * n + i] = r->dir_y, cols[5 * n + i] = r->dir_z;
        cols[6 * n + i] = r->tnear, cols[7 * n + i] = r->tfar;
    }
    soa.org_x = cols, soa.org_y = cols + n, soa.org_z = cols + 2 * n;
    soa.dir_x = cols + 3 * n, soa.dir_y = cols + 4 * n, soa.dir_z = cols + 5 * n;
    soa.tnear = cols + 6 * n, soa.tfar = cols + 7 * n;
    soa_hits.t = cols + 8 * n, soa_hits.prim = soa_prim, soa_hits.u = cols + 9 * n, soa_hits.v = cols + 10 * n;
    CHECK(cellrt_intersect_soa(accel, &soa, &soa_hits, n) == CELLRT_SUCCESS);
    CHECK(cellrt_occluded_soa(accel, &soa, soa_occ, n) == CELLRT_SUCCESS);
    for (i = 0; i < n; ++i) {
        const cellrt_hit s = {soa_hits.t[i], soa_hits.prim[i], soa_hits.u[i], soa_hits.v[i]};
        const cellrt_hit* want = &ref->hits[i];
        if (!same_hit(want, &got[i]) || !same_hit(want, &s) || ref->occluded[i] != got_occ[i] ||
            ref->occluded[i] != soa_occ[i]) {
            if (mismatches++ < 3)
                fprintf(stderr, "%s, ray %zu: brute prim %u t %a occluded %d; got prim %u t %a occluded %d, soa prim %u\n",
                        config, i, want->prim, want->t, ref->occluded[i], got[i].prim, got[i].t, got_occ[i], s.prim);
        }
    }
    /* Without tnear and tfar the SoA rays are unbounded; without u and v only t and prim are written. */
    soa.tnear = NULL, soa.tfar = NULL, soa_hits.u = NULL, soa_hits.v = NULL;
    for (i = 0; i < n; ++i) cols[9 * n + i] = -1.f;
    CHECK(cellrt_intersect_soa(accel, &soa, &soa_hits, n) == CELLRT_SUCCESS);
    for (i = 0; i < n; ++i)
        if (ref->unbounded[i].prim != soa_hits.prim[i] || !same_float(ref->unbounded[i].t, soa_hits.t[i]) ||
            cols[9 * n + i] != -1.f) {
            if (mismatches++ < 3)
                fprintf(stderr, "%s unbounded, ray %zu: brute prim %u t %a; soa prim %u t %a\n", config, i,
                        ref->unbounded[i].prim, ref->unbounded[i].t, soa_hits.prim[i], soa_hits.t[i]);
        }
    CHECK(cellrt_accel_release(accel) == CELLRT_SUCCESS);
    free(got), free(got_occ), free(soa_occ), free(cols), free(soa_prim);
    return mismatches;
}

/* Every kind but Embree, whose own triangle test agrees with cellrt's only up to rounding
 * (tests/test_embree.cpp compares it with a tolerance). */
static const char* const kConfigs[] = {"kd",  "bih+auto", "bvh",    "auto",
                                       "kd:rec", "kd+auto", "kd+portable@leaf_size=2", "bih"};
enum { kAllConfigs = sizeof kConfigs / sizeof kConfigs[0] };

static void compare_all(cellrt_scene scene, const char* name, size_t n, size_t configs) {
    struct Reference ref = make_reference(scene, n);
    size_t k;
    CHECK(ref.hit_count > 0); /* a scene every ray misses would test nothing */
    for (k = 0; k < configs; ++k) {
        const long mismatches = compare_with_brute(scene, kConfigs[k], &ref);
        CHECK(mismatches == 0);
        printf("%s, %s: %zu rays (%ld hits), %ld differ from brute force\n", name, kConfigs[k], n, ref.hit_count,
               mismatches);
    }
    free_reference(&ref);
}

/* A UV sphere of shared vertices: neighbouring triangles share their edges exactly. */
static cellrt_scene make_sphere(cellrt_device device, int segments, int rings) {
    const size_t nv = (size_t)(rings + 1) * segments;
    float* v = malloc(3 * nv * sizeof *v);
    uint32_t* idx = malloc(6 * nv * sizeof *idx);
    size_t nt = 0;
    int r, s;
    cellrt_scene scene;
    for (r = 0; r <= rings; ++r)
        for (s = 0; s < segments; ++s) {
            const double th = 3.14159265358979 * r / rings, ph = 6.28318530717959 * s / segments;
            float* p = v + 3 * ((size_t)r * segments + s);
            p[0] = (float)(sin(th) * cos(ph)), p[1] = (float)cos(th), p[2] = (float)(sin(th) * sin(ph));
        }
    for (r = 0; r < rings; ++r)
        for (s = 0; s < segments; ++s) {
            const uint32_t a = (uint32_t)(r * segments + s), b = (uint32_t)(r * segments + (s + 1) % segments);
            const uint32_t c = a + (uint32_t)segments, d = b + (uint32_t)segments;
            idx[3 * nt] = a, idx[3 * nt + 1] = b, idx[3 * nt + 2] = c, ++nt;
            idx[3 * nt] = b, idx[3 * nt + 1] = d, idx[3 * nt + 2] = c, ++nt;
        }
    scene = cellrt_scene_new(device, v, nv, idx, nt);
    free(v), free(idx);
    return scene;
}

/* Triangles of random corners in a unit cube, overlapping one another. */
static cellrt_scene make_soup(cellrt_device device, size_t nt) {
    float* v = malloc(9 * nt * sizeof *v);
    uint32_t* idx = malloc(3 * nt * sizeof *idx);
    size_t i;
    cellrt_scene scene;
    for (i = 0; i < 3 * nt; ++i) {
        const float c[3] = {uniform(0.f, 1.f), uniform(0.f, 1.f), uniform(0.f, 1.f)};
        /* Each triangle small: corners near its first one. */
        const size_t first = 3 * (i - i % 3);
        v[3 * i] = i % 3 ? v[first] + 0.1f * c[0] : c[0];
        v[3 * i + 1] = i % 3 ? v[first + 1] + 0.1f * c[1] : c[1];
        v[3 * i + 2] = i % 3 ? v[first + 2] + 0.1f * c[2] : c[2];
        idx[i] = (uint32_t)(3 * nt - 1 - i); /* indices in an order of their own */
    }
    scene = cellrt_scene_new(device, v, 3 * nt, idx, nt);
    free(v), free(idx);
    return scene;
}

static int part_hits(void) {
    cellrt_device device = cellrt_device_new();
    cellrt_scene sphere = make_sphere(device, 48, 24), soup = make_soup(device, 3000);
    cellrt_scene city = cellrt_scene_load(device, "builtin:city?tris=8000");
    size_t count = 0;
    CHECK(sphere && soup && city);
    CHECK(cellrt_scene_get_info(sphere, &count, NULL, NULL) == CELLRT_SUCCESS && count == 2 * 48 * 24);
    compare_all(sphere, "sphere", 4000, kAllConfigs);
    compare_all(soup, "soup", 4000, kAllConfigs);
    compare_all(city, "builtin:city", 4000, kAllConfigs);
    CHECK(cellrt_scene_release(sphere) == CELLRT_SUCCESS);
    CHECK(cellrt_scene_release(soup) == CELLRT_SUCCESS);
    CHECK(cellrt_scene_release(city) == CELLRT_SUCCESS);
    CHECK(cellrt_device_release(device) == CELLRT_SUCCESS);
    return failures ? 1 : 0;
}

static int part_shared(const char* dir) {
    char path[4096];
    FILE* f;
    cellrt_device device;
    cellrt_scene scene;
    snprintf(path, sizeof path, "%s/bunny/bunny.json", dir);
    if ((f = fopen(path, "r")) == NULL) {
        printf("skipped: %s is absent\n", path);
        return 77;
    }
    fclose(f);
    device = cellrt_device_new();
    scene = cellrt_scene_load(device, path);
    CHECK(scene != NULL);
    if (scene) compare_all(scene, path, 1000, 4); /* the first four kinds: the scene takes long to build */
    CHECK(cellrt_scene_release(scene) == CELLRT_SUCCESS);
    CHECK(cellrt_device_release(device) == CELLRT_SUCCESS);
    return failures ? 1 : 0;
}

struct Calls {
    int count;
    cellrt_error code;
    char message[512];
};

static void on_error(void* user, cellrt_error code, const char* message) {
    struct Calls* c = user;
    ++c->count;
    c->code = code;
    snprintf(c->message, sizeof c->message, "%s", message);
}

static int part_errors(void) {
    const float quad[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint32_t tris[6] = {0, 1, 2, 0, 2, 3};
    const uint32_t bad[6] = {0, 1, 2, 0, 2, 4};
    float nan_quad[12];
    cellrt_device device = cellrt_device_new(), other = cellrt_device_new();
    cellrt_scene scene, empty;
    cellrt_accel accel, fallback;
    cellrt_ray ray = {0.75f, 0.25f, 1.f, 0.f, 0.f, 0.f, -1.f, INFINITY}; /* hits triangle 0 at t = 1 */
    cellrt_hit hit;
    uint8_t occ = 7;
    cellrt_rays_soa soa;
    cellrt_hits_soa soa_hits;
    float t;
    uint32_t prim;
    struct Calls calls = {0, CELLRT_SUCCESS, ""};
    const char* message = NULL;

    CHECK(device && other && device != other);
    CHECK(cellrt_device_get_error(device, &message) == CELLRT_SUCCESS && strcmp(message, "") == 0);
    CHECK(strcmp(cellrt_error_name(CELLRT_ERROR_INVALID_CONFIG), "CELLRT_ERROR_INVALID_CONFIG") == 0);
    CHECK(strcmp(cellrt_error_name((cellrt_error)99), "CELLRT_ERROR_UNRECOGNISED") == 0);

    /* Scenes: handles, NULL arrays, counts, indices, non-finite vertices. */
    CHECK(cellrt_scene_new(NULL, quad, 4, tris, 2) == NULL);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_scene_new: device is NULL");
    CHECK(cellrt_scene_new((cellrt_device)(uintptr_t)987654321u, quad, 4, tris, 2) == NULL);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "device is not a live device handle");
    CHECK(cellrt_scene_new(device, NULL, 4, tris, 2) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "vertices is NULL");
    CHECK(cellrt_scene_new(device, quad, 4, NULL, 2) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "indices is NULL");
    CHECK(cellrt_scene_new(device, quad, 4, bad, 2) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "index 2 of triangle 1 is 4, beyond the 4 vertices");
    CHECK(cellrt_scene_new(device, quad, 3, tris, 2) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "index 2 of triangle 1 is 3, beyond the 3 vertices");
    CHECK(cellrt_scene_new(device, quad, SIZE_MAX, tris, 2) == NULL); /* refused before any vertex is read */
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "vertex_count");
    CHECK(cellrt_scene_new(device, quad, 4, tris, (size_t)UINT32_MAX) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "triangle_count 4294967295 is too large");
    memcpy(nan_quad, quad, sizeof quad);
    nan_quad[7] = NAN;
    CHECK(cellrt_scene_new(device, nan_quad, 4, tris, 2) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "vertex 2 has a non-finite coordinate");
    nan_quad[7] = 1.f, nan_quad[9] = -INFINITY;
    CHECK(cellrt_scene_new(device, nan_quad, 4, tris, 2) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "vertex 3 has a non-finite coordinate");
    CHECK(cellrt_scene_load(device, NULL) == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "path is NULL");
    CHECK(cellrt_scene_load(device, "no/such/file.obj") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_IO, "no/such/file.obj: no such file");
    CHECK(cellrt_scene_load(device, "builtin:nosuch") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_IO, "nosuch");
    CHECK(cellrt_scene_get_info(NULL, NULL, NULL, NULL) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_scene_get_info: scene is NULL");
    empty = cellrt_scene_new(device, NULL, 0, NULL, 0); /* no triangles: every ray misses */
    CHECK(empty != NULL);
    scene = cellrt_scene_new(device, quad, 4, tris, 2);
    CHECK(scene != NULL);

    /* Accelerators: handles and configurations. */
    CHECK(cellrt_accel_new(NULL, "kd") == NULL);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_accel_new: scene is NULL");
    CHECK(cellrt_accel_new((cellrt_scene)device, "kd") == NULL); /* a device is no scene */
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "scene is not a live scene handle");
    CHECK(cellrt_accel_new(scene, "nosuch") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "config 'nosuch'");
    CHECK(cellrt_accel_new(scene, "") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "config ''");
    CHECK(cellrt_accel_new(scene, "kd:nosuch") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "nosuch");
    CHECK(cellrt_accel_new(scene, "kd+nosuch") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "nosuch");
    CHECK(cellrt_accel_new(scene, "kd@leaf_size") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "must have the form NAME=VALUE");
    CHECK(cellrt_accel_new(scene, "kd@nosuch=1") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "nosuch");
    CHECK(cellrt_accel_new(scene, "kd@leaf_size=-5") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "leaf_size");
    /* A tree's single-ray kernel with SIMD packets, which would replace it (built and reported as
     * asked until found by audit, 2026-12-07); the BVH's traversals take a SIMD set. */
    CHECK(cellrt_accel_new(scene, "kd:rec+auto") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG,
                "'kd:rec+auto' names a single-ray kernel ('rec') and SIMD packets ('auto'), which would replace it");
    CHECK(cellrt_accel_new(scene, "bih:branchless+avx2") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "names a single-ray kernel ('branchless')");
    CHECK(cellrt_accel_new(scene, "brute:loop+sse") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "names a single-ray kernel ('loop')");
    accel = cellrt_accel_new(scene, "bvh:paired+auto");
    CHECK(accel != NULL && cellrt_accel_release(accel) == CELLRT_SUCCESS);
    fallback = cellrt_accel_new(scene, NULL); /* NULL: the CPU's default, auto@packets=bvh */
    CHECK(fallback != NULL);
    /* What an accelerator is: NULL's configuration named in full, a given one in canonical form. */
    {
        const char *config = NULL, *where = NULL;
        double seconds = -1.0;
        size_t bytes = 0;
        CHECK(cellrt_accel_get_info(fallback, &config, &where, &seconds, &bytes) == CELLRT_SUCCESS);
        CHECK(config != NULL && strcmp(config, "auto@packets=bvh") == 0);
        CHECK(where != NULL && strcmp(where, "cpu") == 0);
        CHECK(seconds >= 0.0 && bytes > 0);
        CHECK(cellrt_accel_get_info(fallback, NULL, NULL, NULL, NULL) == CELLRT_SUCCESS);
        accel = cellrt_accel_new_on(scene, "kd:rec@leaf_size=2,bins=64", "cpu");
        CHECK(accel != NULL);
        CHECK(cellrt_accel_get_info(accel, &config, &where, NULL, NULL) == CELLRT_SUCCESS);
        CHECK(strcmp(config, "kd:rec@bins=64,leaf_size=2") == 0 && strcmp(where, "cpu") == 0);
        CHECK(cellrt_accel_release(accel) == CELLRT_SUCCESS);
        CHECK(cellrt_accel_get_info(accel, &config, NULL, NULL, NULL) == CELLRT_ERROR_INVALID_HANDLE);
        CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_accel_get_info: accel is not a live accel handle");
        CHECK(cellrt_accel_get_info((cellrt_accel)scene, NULL, NULL, NULL, NULL) == CELLRT_ERROR_INVALID_HANDLE);
        CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "accel is not a live accel handle");
    }
    /* Where it runs: the CPU by name or by NULL; an unknown place refused; the GPU, or the reason
     * there is none (CI has none: the GPU's answers are tested by the C++ suite where it has one). */
    CHECK(cellrt_accel_new_on(scene, "kd", "tpu") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "config 'kd' on 'tpu': device 'tpu' is not one of: cpu, cuda");
    CHECK(cellrt_accel_new_on(scene, "kd+avx2", "cuda") == NULL);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "config 'kd+avx2' on 'cuda'");
    for (int k = 0; k < 2; ++k) {
        cellrt_accel here = cellrt_accel_new_on(scene, "kd", k ? "cpu" : NULL);
        CHECK(here != NULL && cellrt_accel_release(here) == CELLRT_SUCCESS);
    }
    accel = cellrt_accel_new_on(scene, "bih", "cuda");
    if (accel) {
        const char *config = NULL, *where = NULL;
        CHECK(cellrt_accel_get_info(accel, &config, &where, NULL, NULL) == CELLRT_SUCCESS);
        CHECK(strcmp(config, "bih+off") == 0 && strcmp(where, "cuda") == 0);
        CHECK(cellrt_intersect(accel, &ray, &hit, 1) == CELLRT_SUCCESS);
        CHECK(cellrt_accel_release(accel) == CELLRT_SUCCESS);
    } else {
        CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "config 'bih' on 'cuda': device 'cuda': ");
    }
    accel = cellrt_accel_new(empty, "bih");
    CHECK(accel != NULL);
    CHECK(cellrt_intersect(accel, &ray, &hit, 1) == CELLRT_SUCCESS && hit.prim == CELLRT_INVALID_ID && isinf(hit.t));
    CHECK(cellrt_accel_release(accel) == CELLRT_SUCCESS);

    /* Queries: handles, NULL arrays; a count of 0 needs no arrays; a bad ray misses. */
    CHECK(cellrt_intersect(fallback, &ray, &hit, 1) == CELLRT_SUCCESS && hit.prim == 0 && hit.t == 1.f);
    CHECK(cellrt_occluded(fallback, &ray, &occ, 1) == CELLRT_SUCCESS && occ == 1);
    CHECK(cellrt_intersect(NULL, &ray, &hit, 1) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_intersect: accel is NULL");
    CHECK(cellrt_intersect((cellrt_accel)scene, &ray, &hit, 1) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "accel is not a live accel handle");
    CHECK(cellrt_intersect(fallback, NULL, &hit, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "cellrt_intersect: rays is NULL, count 1");
    CHECK(cellrt_intersect(fallback, &ray, NULL, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "hits is NULL");
    CHECK(cellrt_intersect(fallback, NULL, NULL, 0) == CELLRT_SUCCESS);
    /* Counts whose arrays cannot exist: refused before any ray is read (a crash until 2026-12-07). */
    CHECK(cellrt_intersect(fallback, &ray, &hit, SIZE_MAX / 16) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "is too large: rays would take more than");
    CHECK(cellrt_occluded(fallback, &ray, &occ, SIZE_MAX / 16) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "is too large: rays would take more than");
    {
        float x = 0.f;
        const cellrt_rays_soa soa = {&x, &x, &x, &x, &x, &x, NULL, NULL};
        uint32_t prim = 0;
        const cellrt_hits_soa out = {&x, &prim, NULL, NULL};
        CHECK(cellrt_intersect_soa(fallback, &soa, &out, SIZE_MAX / 2) == CELLRT_ERROR_INVALID_ARGUMENT);
        CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "is too large");
        CHECK(cellrt_occluded_soa(fallback, &soa, &occ, SIZE_MAX / 2) == CELLRT_ERROR_INVALID_ARGUMENT);
        CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "is too large");
    }
    CHECK(cellrt_occluded(fallback, NULL, &occ, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "cellrt_occluded: rays is NULL");
    CHECK(cellrt_occluded(fallback, &ray, NULL, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "occluded is NULL");
    CHECK(cellrt_occluded(NULL, &ray, &occ, 1) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_occluded: accel is NULL");
    CHECK(cellrt_occluded(fallback, NULL, NULL, 0) == CELLRT_SUCCESS);
    ray.org_x = NAN;
    CHECK(cellrt_intersect(fallback, &ray, &hit, 1) == CELLRT_SUCCESS && hit.prim == CELLRT_INVALID_ID);
    CHECK(cellrt_occluded(fallback, &ray, &occ, 1) == CELLRT_SUCCESS && occ == 0);
    ray.org_x = 0.75f, ray.tfar = 0.5f; /* the quad at t = 1 lies beyond tfar */
    CHECK(cellrt_intersect(fallback, &ray, &hit, 1) == CELLRT_SUCCESS && hit.prim == CELLRT_INVALID_ID);
    ray.tfar = INFINITY;

    memset(&soa, 0, sizeof soa);
    soa.org_x = &ray.org_x, soa.org_y = &ray.org_y, soa.org_z = &ray.org_z;
    soa.dir_x = &ray.dir_x, soa.dir_y = NULL, soa.dir_z = &ray.dir_z;
    soa_hits.t = &t, soa_hits.prim = &prim, soa_hits.u = NULL, soa_hits.v = NULL;
    CHECK(cellrt_intersect_soa(fallback, NULL, &soa_hits, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "cellrt_intersect_soa: rays is NULL");
    CHECK(cellrt_intersect_soa(fallback, &soa, &soa_hits, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "rays->dir_y is NULL");
    CHECK(cellrt_occluded_soa(fallback, &soa, &occ, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "cellrt_occluded_soa: rays->dir_y is NULL");
    soa.dir_y = &ray.dir_y;
    CHECK(cellrt_intersect_soa(fallback, &soa, NULL, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "hits is NULL");
    soa_hits.t = NULL;
    CHECK(cellrt_intersect_soa(fallback, &soa, &soa_hits, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "hits->t is NULL");
    soa_hits.t = &t, soa_hits.prim = NULL;
    CHECK(cellrt_intersect_soa(fallback, &soa, &soa_hits, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "hits->prim is NULL");
    soa_hits.prim = &prim;
    CHECK(cellrt_intersect_soa(fallback, &soa, &soa_hits, 1) == CELLRT_SUCCESS && prim == 0 && t == 1.f);
    CHECK(cellrt_occluded_soa(fallback, &soa, NULL, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "occluded is NULL");
    CHECK(cellrt_occluded_soa(NULL, &soa, &occ, 1) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "accel is NULL");
    occ = 7;
    CHECK(cellrt_occluded_soa(fallback, &soa, &occ, 1) == CELLRT_SUCCESS && occ == 1);
    CHECK(cellrt_intersect_soa(fallback, NULL, NULL, 0) == CELLRT_SUCCESS);
    CHECK(cellrt_occluded_soa(fallback, NULL, NULL, 0) == CELLRT_SUCCESS);

    /* Rays Embree refuses (a negative tnear) are found before any ray is traced: nothing is written,
     * the code is INVALID_ARGUMENT and the message names the caller's index, not the index within the
     * chunk the call traced it in. Where cellrt was built without Embree there is no such accelerator. */
    {
        enum { kRays = 20000, kBad = 19000 };
        static cellrt_ray rays[kRays];
        static cellrt_hit hits[kRays];
        static uint8_t occluded[kRays];
        cellrt_accel embree = cellrt_accel_new(scene, "embree");
        size_t i;
        int untouched = 1;
        if (!embree) {
            CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "unknown accelerator 'embree'");
        } else {
            for (i = 0; i < kRays; ++i) rays[i] = ray;
            rays[kBad].tnear = -1.f;
            memset(hits, 0xAB, sizeof hits);
            memset(occluded, 0xAB, sizeof occluded);
            CHECK(cellrt_intersect(embree, rays, hits, kRays) == CELLRT_ERROR_INVALID_ARGUMENT);
            CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "ray 19000 of the batch has tnear -1");
            CHECK(cellrt_occluded(embree, rays, occluded, kRays) == CELLRT_ERROR_INVALID_ARGUMENT);
            CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "ray 19000 of the batch has tnear -1");
            for (i = 0; i < sizeof hits; ++i) untouched &= ((const unsigned char*)hits)[i] == 0xAB;
            for (i = 0; i < kRays; ++i) untouched &= occluded[i] == 0xAB;
            CHECK(untouched);
            rays[kBad].tnear = 0.f;
            CHECK(cellrt_occluded(embree, rays, occluded, kRays) == CELLRT_SUCCESS && occluded[kBad] == 1);
            CHECK(cellrt_accel_release(embree) == CELLRT_SUCCESS);
        }
    }

    /* The error function: called with the code and the message on a failure, not once unset. */
    CHECK(cellrt_device_set_error_function(NULL, on_error, &calls) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_device_set_error_function: device is NULL");
    CHECK(cellrt_device_set_error_function(device, on_error, &calls) == CELLRT_SUCCESS);
    CHECK(cellrt_intersect(fallback, NULL, &hit, 1) == CELLRT_ERROR_INVALID_ARGUMENT);
    CHECK(calls.count == 1 && calls.code == CELLRT_ERROR_INVALID_ARGUMENT && strstr(calls.message, "rays is NULL"));
    CHECK(cellrt_intersect(fallback, &ray, &hit, 1) == CELLRT_SUCCESS && calls.count == 1);
    CHECK(cellrt_device_get_error(other, NULL) == CELLRT_SUCCESS); /* errors stay on their device */
    CHECK(cellrt_device_set_error_function(device, NULL, NULL) == CELLRT_SUCCESS);
    CHECK(cellrt_accel_new(scene, "nosuch") == NULL && calls.count == 1);
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_CONFIG, "nosuch");

    /* Reference counts: NULL is released as free(NULL) is; a release too many, a retain of NULL and a
     * released handle are refused; handles are released in any order. */
    CHECK(cellrt_device_release(NULL) == CELLRT_SUCCESS);
    CHECK(cellrt_scene_release(NULL) == CELLRT_SUCCESS);
    CHECK(cellrt_accel_release(NULL) == CELLRT_SUCCESS);
    CHECK(cellrt_device_retain(NULL) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_device_retain: device is NULL");
    CHECK(cellrt_scene_retain(NULL) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_scene_retain: scene is NULL");
    CHECK(cellrt_accel_retain(NULL) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_accel_retain: accel is NULL");
    CHECK(cellrt_accel_release((cellrt_accel)scene) == CELLRT_ERROR_INVALID_HANDLE); /* a scene is no accel */
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "accel is not a live accel handle");
    CHECK(cellrt_accel_retain(fallback) == CELLRT_SUCCESS);
    CHECK(cellrt_scene_release(scene) == CELLRT_SUCCESS);   /* the accelerator keeps its scene */
    CHECK(cellrt_device_release(device) == CELLRT_SUCCESS); /* and the scene its device */
    CHECK(cellrt_scene_release(scene) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_scene_release: scene is not a live scene handle");
    CHECK(cellrt_device_release(device) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_device_release: device is not a live device handle");
    CHECK(cellrt_scene_new(device, quad, 4, tris, 2) == NULL);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "device is not a live device handle");
    CHECK(cellrt_accel_release(fallback) == CELLRT_SUCCESS); /* one of two references */
    CHECK(cellrt_intersect(fallback, &ray, &hit, 1) == CELLRT_SUCCESS && hit.prim == 0);
    CHECK(cellrt_intersect(fallback, NULL, &hit, 1) == CELLRT_ERROR_INVALID_ARGUMENT); /* to the released device */
    CHECK_ERROR(device, CELLRT_ERROR_INVALID_ARGUMENT, "rays is NULL");
    CHECK(cellrt_accel_release(fallback) == CELLRT_SUCCESS);
    CHECK(cellrt_accel_release(fallback) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "cellrt_accel_release: accel is not a live accel handle");
    CHECK(cellrt_intersect(fallback, &ray, &hit, 1) == CELLRT_ERROR_INVALID_HANDLE);
    CHECK_ERROR(NULL, CELLRT_ERROR_INVALID_HANDLE, "accel is not a live accel handle");
    CHECK(cellrt_scene_release(empty) == CELLRT_SUCCESS);
    CHECK(cellrt_device_release(other) == CELLRT_SUCCESS);
    printf("%s\n", failures ? "error paths: FAILED" : "error paths: all refused as documented");
    return failures ? 1 : 0;
}

enum { kThreads = 4, kThreadRays = 20000 };

struct Job {
    cellrt_device device;
    cellrt_accel accel;
    const cellrt_ray* rays;
    const cellrt_hit* want;
    int index, mismatches;
    int error_ok;
};

static void* run_job(void* arg) {
    struct Job* job = arg;
    cellrt_hit* got = malloc(kThreadRays * sizeof *got);
    const char* message = NULL;
    char expected[64];
    int round, i;
    for (round = 0; round < 5; ++round) {
        if (cellrt_intersect(job->accel, job->rays, got, kThreadRays) != CELLRT_SUCCESS) ++job->mismatches;
        for (i = 0; i < kThreadRays; ++i)
            if (!same_hit(&got[i], &job->want[i])) ++job->mismatches;
        /* Each thread's own error, read back by that thread alone. */
        if (cellrt_intersect(job->accel, NULL, got, (size_t)(job->index + 1)) != CELLRT_ERROR_INVALID_ARGUMENT)
            ++job->mismatches;
    }
    snprintf(expected, sizeof expected, "rays is NULL, count %d", job->index + 1);
    job->error_ok = cellrt_device_get_error(job->device, &message) == CELLRT_ERROR_INVALID_ARGUMENT &&
                    strstr(message, expected) != NULL;
    free(got);
    return NULL;
}

static pthread_mutex_t calls_mutex = PTHREAD_MUTEX_INITIALIZER;
static void on_error_locked(void* user, cellrt_error code, const char* message) {
    (void)code, (void)message;
    pthread_mutex_lock(&calls_mutex);
    ++*(int*)user;
    pthread_mutex_unlock(&calls_mutex);
}

static int part_threads(void) {
    cellrt_device device = cellrt_device_new();
    cellrt_scene scene = cellrt_scene_load(device, "builtin:city?tris=20000");
    const char* const configs[] = {"kd", "kd+auto", "bih", "bvh"};
    cellrt_ray* rays = malloc(kThreadRays * sizeof *rays);
    cellrt_hit* want = malloc(kThreadRays * sizeof *want);
    int errors_seen = 0;
    size_t k;
    CHECK(scene != NULL);
    make_rays(scene, rays, kThreadRays);
    CHECK(cellrt_device_set_error_function(device, on_error_locked, &errors_seen) == CELLRT_SUCCESS);
    for (k = 0; k < sizeof configs / sizeof configs[0]; ++k) {
        cellrt_accel accel = cellrt_accel_new(scene, configs[k]);
        pthread_t threads[kThreads];
        struct Job jobs[kThreads];
        int i;
        CHECK(accel != NULL);
        CHECK(cellrt_intersect(accel, rays, want, kThreadRays) == CELLRT_SUCCESS);
        for (i = 0; i < kThreads; ++i) {
            jobs[i].device = device, jobs[i].accel = accel, jobs[i].rays = rays, jobs[i].want = want;
            jobs[i].index = i, jobs[i].mismatches = 0, jobs[i].error_ok = 0;
            CHECK(pthread_create(&threads[i], NULL, run_job, &jobs[i]) == 0);
        }
        for (i = 0; i < kThreads; ++i) {
            CHECK(pthread_join(threads[i], NULL) == 0);
            CHECK(jobs[i].mismatches == 0);
            CHECK(jobs[i].error_ok);
        }
        printf("%s: %d threads at once, %d x 5 x %d rays, equal to one thread alone\n", configs[k], kThreads,
               kThreads, kThreadRays);
        CHECK(cellrt_accel_release(accel) == CELLRT_SUCCESS);
    }
    CHECK(errors_seen == 4 * kThreads * 5);
    CHECK(cellrt_device_get_error(device, NULL) == CELLRT_SUCCESS); /* the threads' errors were theirs */
    free(rays), free(want);
    CHECK(cellrt_scene_release(scene) == CELLRT_SUCCESS);
    CHECK(cellrt_device_release(device) == CELLRT_SUCCESS);
    return failures ? 1 : 0;
}

/* "exit": handles released by an atexit handler registered before the first cellrt call, which runs
 * after the statics made since are gone (found by review, 2026-12-07: every release returned
 * INVALID_HANDLE, the handle table destroyed); a failed call's code is still returned there. The
 * process exits 0 only when each release succeeded. */
static cellrt_device exit_device;
static cellrt_scene exit_scene;
static cellrt_accel exit_accel;
static void release_at_exit(void) {
    const int ok = cellrt_accel_release(exit_accel) == CELLRT_SUCCESS &&
                   cellrt_scene_release(exit_scene) == CELLRT_SUCCESS &&
                   cellrt_device_release(exit_device) == CELLRT_SUCCESS &&
                   cellrt_device_release(exit_device) == CELLRT_ERROR_INVALID_HANDLE;
    if (!ok) {
        fprintf(stderr, "releases at exit failed\n");
        _exit(1);
    }
}

static int part_exit(void) {
    static const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const uint32_t i[3] = {0, 1, 2};
    CHECK(atexit(release_at_exit) == 0);
    exit_device = cellrt_device_new();
    exit_scene = cellrt_scene_new(exit_device, v, 3, i, 1);
    exit_accel = cellrt_accel_new(exit_scene, "kd");
    CHECK(exit_device && exit_scene && exit_accel);
    return failures ? 1 : 0;
}

int main(int argc, char** argv) {
    if (argc >= 2 && strcmp(argv[1], "hits") == 0) return part_hits();
    if (argc >= 3 && strcmp(argv[1], "shared") == 0) return part_shared(argv[2]);
    if (argc >= 2 && strcmp(argv[1], "errors") == 0) return part_errors();
    if (argc >= 2 && strcmp(argv[1], "threads") == 0) return part_threads();
    if (argc >= 2 && strcmp(argv[1], "exit") == 0) return part_exit();
    fprintf(stderr, "usage: %s hits | shared SCENES_DIR | errors | threads | exit\n", argv[0]);
    return 2;
}
