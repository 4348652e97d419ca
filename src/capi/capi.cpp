// The C API (include/cellrt/cellrt.h) over the registry: handles to objects (handles.hpp), errors as
// codes recorded per thread and device, and the queries over copies of the caller's rays in chunks.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <new>
#include <span>
#include <string>
#include <unordered_map>

#include "cellrt/accel.hpp"
#include "cellrt/cellrt.h"
#include "cellrt/error.hpp"
#include "cellrt/scene.hpp"
#include "handles.hpp"

namespace cellrt::capi {
namespace {

// Never destroyed: a C program's atexit handler, registered before its first cellrt call, runs after
// the statics made since are gone, and may still release its handles (as may threads running at exit).
HandleTable& table() {
    static HandleTable& t = *new HandleTable;
    return t;
}

// An error raised inside a C function, turned into its code at the function's boundary.
struct Failure {
    cellrt_error code;
    std::string message;
};

[[noreturn]] void fail(cellrt_error code, std::string message) { throw Failure{code, std::move(message)}; }

struct Record {
    cellrt_error code = CELLRT_SUCCESS;
    std::string message;
};

// The calling thread's latest error per device id (0: errors with no device). Ids are never reused,
// so a record never outlives its meaning. The records of devices released since, read or not, are
// dropped whenever the map has doubled since the last sweep, so that a program making a device per
// job does not grow without bound (unread ones were kept: a program that takes its errors through
// the error function alone grew by about 140 bytes a device; found by audit, 2026-12-07).
struct Records {
    std::unordered_map<std::uint64_t, Record> map;
    std::size_t sweep_at = 64;
    ~Records();
};
// Trivially destructible, so readable after the thread's records are gone (an atexit handler's call
// on the main thread comes after them): errors are then returned but not recorded.
thread_local bool t_records_gone = false;
Records::~Records() { t_records_gone = true; }

Records* records() {
    if (t_records_gone) return nullptr;
    thread_local Records r;
    return &r;
}

void record(std::uint64_t device, cellrt_error code, const char* message) {
    Records* all = records();
    if (!all) return;
    Record& r = all->map[device];
    r.code = code;
    r.message = message;
    if (all->map.size() < all->sweep_at) return;
    std::erase_if(all->map, [](const auto& entry) {
        return entry.first != 0 && !table().find<Device>(entry.first);
    });
    all->sweep_at = std::max<std::size_t>(64, 2 * all->map.size());
}

template <class Handle>
std::uint64_t id_of(Handle h) { return static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(h)); }
template <class Handle>
Handle handle_of(std::uint64_t id) { return reinterpret_cast<Handle>(static_cast<std::uintptr_t>(id)); }

cellrt_error report(const std::shared_ptr<Device>& device, cellrt_error code, const char* message) noexcept {
    try {
        record(device ? device->id : 0, code, message);
    } catch (...) {  // no memory for the record: the code is still returned
    }
    if (device) {
        cellrt_error_function function;
        void* user;
        {
            const std::lock_guard lock(device->mutex);
            function = device->error_function;
            user = device->error_user;
        }
        if (function) function(user, code, message);
    }
    return code;
}

// Runs `body` as the C function `name`: its failures, cellrt::Error and anything else thrown become
// the returned code, recorded for `device` (which `body` sets once it has found it).
template <class Body>
cellrt_error guarded(const char* name, std::shared_ptr<Device>& device, Body&& body) noexcept {
    try {
        try {
            body();
            return CELLRT_SUCCESS;
        } catch (const Failure& f) {
            return report(device, f.code, (std::string(name) + ": " + f.message).c_str());
        } catch (const std::bad_alloc&) {
            return report(device, CELLRT_ERROR_OUT_OF_MEMORY, (std::string(name) + ": out of memory").c_str());
        } catch (const std::exception& e) {
            return report(device, CELLRT_ERROR_UNKNOWN, (std::string(name) + ": " + e.what()).c_str());
        }
    } catch (...) {  // building the message failed, or an exception of no standard type
        return report(device, CELLRT_ERROR_OUT_OF_MEMORY, "out of memory");
    }
}

template <class T>
std::shared_ptr<T> find(std::uint64_t id, const char* what) {
    auto object = table().find<T>(id);
    if (!object) {
        if (id == 0) fail(CELLRT_ERROR_INVALID_HANDLE, std::string(what) + " is NULL");
        fail(CELLRT_ERROR_INVALID_HANDLE, std::string(what) + " is not a live " + what + " handle");
    }
    return object;
}

template <class T>
cellrt_error count(const char* name, std::uint64_t id, const char* what, int delta) noexcept {
    std::shared_ptr<Device> device;
    Object removed;  // dies after the table's lock is released
    return guarded(name, device, [&] {
        if (delta < 0 && id == 0) return;  // release(NULL) does nothing, as free(NULL)
        if (!table().count<T>(id, delta, removed))
            fail(CELLRT_ERROR_INVALID_HANDLE, std::string(what) + " is " +
                                                  (id == 0 ? "NULL" : "not a live " + std::string(what) + " handle"));
    });
}

std::string str(std::size_t n) { return std::to_string(n); }

std::shared_ptr<SceneData> new_scene(const std::shared_ptr<Device>& device, const float* vertices,
                                     std::size_t vertex_count, const std::uint32_t* indices,
                                     std::size_t triangle_count) {
    if (vertex_count > 0 && !vertices) fail(CELLRT_ERROR_INVALID_ARGUMENT, "vertices is NULL, vertex_count " + str(vertex_count));
    if (triangle_count > 0 && !indices)
        fail(CELLRT_ERROR_INVALID_ARGUMENT, "indices is NULL, triangle_count " + str(triangle_count));
    if (vertex_count > SIZE_MAX / 3 / sizeof(float))
        fail(CELLRT_ERROR_INVALID_ARGUMENT, "vertex_count " + str(vertex_count) + " is too large");
    // A triangle's index must fit a hit's prim below CELLRT_INVALID_ID.
    if (triangle_count >= CELLRT_INVALID_ID)
        fail(CELLRT_ERROR_INVALID_ARGUMENT, "triangle_count " + str(triangle_count) + " is too large (at most " +
                                                str(CELLRT_INVALID_ID - 1) + ")");
    for (std::size_t i = 0; i < 3 * vertex_count; ++i)
        if (!std::isfinite(vertices[i]))
            fail(CELLRT_ERROR_INVALID_ARGUMENT, "vertex " + str(i / 3) + " has a non-finite coordinate");
    auto scene = std::make_shared<SceneData>();
    scene->device = device;
    scene->triangles.resize(triangle_count);
    for (std::size_t t = 0; t < triangle_count; ++t) {
        Vec3 corner[3];
        for (std::size_t k = 0; k < 3; ++k) {
            const std::uint32_t i = indices[3 * t + k];
            if (i >= vertex_count)
                fail(CELLRT_ERROR_INVALID_ARGUMENT, "index " + str(k) + " of triangle " + str(t) + " is " + str(i) +
                                                        ", beyond the " + str(vertex_count) + " vertices");
            corner[k] = {vertices[3 * std::size_t{i}], vertices[3 * std::size_t{i} + 1], vertices[3 * std::size_t{i} + 2]};
        }
        scene->triangles[t] = {corner[0], corner[1], corner[2]};
    }
    return scene;
}

// Rays traced per chunk: copies of the caller's rays into cellrt's own type (their layouts are not
// the same type to C++), large enough for the packet kernels' batches.
constexpr std::size_t kChunk = 1 << 14;

template <class LoadRay>
void chunks(std::size_t count, LoadRay&& load, auto&& trace) {
    std::vector<Ray> rays(std::min(count, kChunk));
    for (std::size_t b = 0; b < count; b += kChunk) {
        const std::size_t n = std::min(kChunk, count - b);
        for (std::size_t i = 0; i < n; ++i) rays[i] = load(b + i);
        trace(b, std::span<const Ray>(rays.data(), n));
    }
}

// Rays the accelerator refuses (Embree's domain) are found before any is traced, so that a refusal
// writes no answer and names the caller's index.
void check_all(const Accelerator& accel, std::size_t count, auto&& load) {
    if (!accel.refuses_rays()) return;
    try {
        chunks(count, load, [&](std::size_t b, std::span<const Ray> rays) { accel.check_rays(rays, b); });
    } catch (const Error& e) {
        fail(CELLRT_ERROR_INVALID_ARGUMENT, e.what());
    }
}

void intersect_all(const Accelerator& accel, std::size_t count, auto&& load, auto&& store) {
    check_all(accel, count, load);
    std::vector<Hit> hits(std::min(count, kChunk));
    chunks(count, load, [&](std::size_t b, std::span<const Ray> rays) {
        accel.intersect(rays, std::span(hits.data(), rays.size()));
        for (std::size_t i = 0; i < rays.size(); ++i)
            store(b + i, hits[i].is_hit() ? hits[i] : Hit{kInfinity, kNoHit, 0.f, 0.f});
    });
}

void occluded_all(const Accelerator& accel, std::size_t count, auto&& load, std::uint8_t* out) {
    check_all(accel, count, load);
    chunks(count, load, [&](std::size_t b, std::span<const Ray> rays) {
        accel.occluded(rays, std::span(out + b, rays.size()));
    });
}

Ray ray_of(const cellrt_ray& r) {
    Ray ray;
    ray.org = {r.org_x, r.org_y, r.org_z};
    ray.tnear = r.tnear;
    ray.dir = {r.dir_x, r.dir_y, r.dir_z};
    ray.tfar = r.tfar;
    return ray;
}

auto soa_loader(const cellrt_rays_soa& s) {
    return [s](std::size_t i) {
        Ray ray;
        ray.org = {s.org_x[i], s.org_y[i], s.org_z[i]};
        ray.dir = {s.dir_x[i], s.dir_y[i], s.dir_z[i]};
        ray.tnear = s.tnear ? s.tnear[i] : 0.f;
        ray.tfar = s.tfar ? s.tfar[i] : kInfinity;
        return ray;
    };
}

// An array of `count` elements of `element` bytes: not NULL unless empty, and no larger than an
// object can be (a count whose bytes overflowed size_t read and wrote past the caller's arrays; found
// by audit, 2026-12-07).
void check_array(const void* p, const char* name, std::size_t count, std::size_t element) {
    if (count > 0 && !p) fail(CELLRT_ERROR_INVALID_ARGUMENT, std::string(name) + " is NULL, count " + str(count));
    if (count > static_cast<std::size_t>(PTRDIFF_MAX) / element)
        fail(CELLRT_ERROR_INVALID_ARGUMENT, "count " + str(count) + " is too large: " + name + " would take more than " +
                                                str(static_cast<std::size_t>(PTRDIFF_MAX)) + " bytes");
}

void check_soa(const cellrt_rays_soa* rays, std::size_t count) {
    if (count == 0) return;
    if (!rays) fail(CELLRT_ERROR_INVALID_ARGUMENT, "rays is NULL, count " + str(count));
    check_array(rays, "each of rays' arrays", count, sizeof(float));
    const struct {
        const float* p;
        const char* name;
    } required[] = {{rays->org_x, "org_x"}, {rays->org_y, "org_y"}, {rays->org_z, "org_z"},
                    {rays->dir_x, "dir_x"}, {rays->dir_y, "dir_y"}, {rays->dir_z, "dir_z"}};
    for (const auto& r : required)
        if (!r.p) fail(CELLRT_ERROR_INVALID_ARGUMENT, std::string("rays->") + r.name + " is NULL, count " + str(count));
}


}  // namespace
}  // namespace cellrt::capi

using namespace cellrt::capi;

extern "C" {

cellrt_device cellrt_device_new(void) {
    std::shared_ptr<Device> none;
    std::uint64_t id = 0;
    guarded("cellrt_device_new", none, [&] {
        id = table().add(std::make_shared<Device>());
    });
    return handle_of<cellrt_device>(id);
}

cellrt_error cellrt_device_retain(cellrt_device device) {
    return count<Device>("cellrt_device_retain", id_of(device), "device", +1);
}

cellrt_error cellrt_device_release(cellrt_device device) {
    return count<Device>("cellrt_device_release", id_of(device), "device", -1);
}

cellrt_error cellrt_device_set_error_function(cellrt_device device, cellrt_error_function function, void* user) {
    std::shared_ptr<Device> d;
    return guarded("cellrt_device_set_error_function", d, [&] {
        const auto found = find<Device>(id_of(device), "device");
        const std::lock_guard lock(found->mutex);
        found->error_function = function;
        found->error_user = user;
    });
}

cellrt_error cellrt_device_get_error(cellrt_device device, const char** message) {
    // Records are kept by id, so a handle that was never live has none, and one released keeps the
    // calling thread's last error recorded on it while it lived, until a sweep of record() drops it
    // (a release too many is recorded under NULL: a dead handle has no device).
    Records* all = records();
    const auto it = all ? all->map.find(id_of(device)) : decltype(all->map)::iterator{};
    if (!all || it == all->map.end()) {
        if (message) *message = "";
        return CELLRT_SUCCESS;
    }
    const cellrt_error code = it->second.code;
    // Once read, the error is gone: "" from then on. Its text stays where the last call pointed.
    if (message) *message = code == CELLRT_SUCCESS ? "" : it->second.message.c_str();
    it->second.code = CELLRT_SUCCESS;
    return code;
}

cellrt_scene cellrt_scene_new(cellrt_device device, const float* vertices, size_t vertex_count,
                              const uint32_t* indices, size_t triangle_count) {
    std::shared_ptr<Device> d;
    std::uint64_t id = 0;
    guarded("cellrt_scene_new", d, [&] {
        d = find<Device>(id_of(device), "device");
        id = table().add(new_scene(d, vertices, vertex_count, indices, triangle_count));
    });
    return handle_of<cellrt_scene>(id);
}

cellrt_scene cellrt_scene_load(cellrt_device device, const char* path) {
    std::shared_ptr<Device> d;
    std::uint64_t id = 0;
    guarded("cellrt_scene_load", d, [&] {
        d = find<Device>(id_of(device), "device");
        if (!path) fail(CELLRT_ERROR_INVALID_ARGUMENT, "path is NULL");
        auto scene = std::make_shared<SceneData>();
        scene->device = d;
        try {
            scene->triangles = cellrt::load_scene(path).triangles;
        } catch (const cellrt::Error& e) {
            fail(CELLRT_ERROR_IO, e.what());
        }
        if (scene->triangles.size() >= CELLRT_INVALID_ID)
            fail(CELLRT_ERROR_INVALID_ARGUMENT, std::string(path) + ": too many triangles");
        id = table().add(std::move(scene));
    });
    return handle_of<cellrt_scene>(id);
}

cellrt_error cellrt_scene_retain(cellrt_scene scene) {
    return count<SceneData>("cellrt_scene_retain", id_of(scene), "scene", +1);
}

cellrt_error cellrt_scene_release(cellrt_scene scene) {
    return count<SceneData>("cellrt_scene_release", id_of(scene), "scene", -1);
}

cellrt_error cellrt_scene_get_info(cellrt_scene scene, size_t* triangle_count, float lo[3], float hi[3]) {
    std::shared_ptr<Device> d;
    return guarded("cellrt_scene_get_info", d, [&] {
        const auto s = find<SceneData>(id_of(scene), "scene");
        d = s->device;
        cellrt::Box3 box;
        for (const cellrt::Triangle& t : s->triangles) box.extend(t.bounds());
        if (triangle_count) *triangle_count = s->triangles.size();
        for (int a = 0; a < 3; ++a) {
            if (lo) lo[a] = box.lo[a];
            if (hi) hi[a] = box.hi[a];
        }
    });
}

namespace {

// cellrt_accel_new and cellrt_accel_new_on: `where` NULL is the CPU, and the message names it only
// when given.
cellrt_accel new_accel(const char* name, cellrt_scene scene, const char* config, const char* where) {
    std::shared_ptr<Device> d;
    std::uint64_t id = 0;
    guarded(name, d, [&] {
        const auto s = find<SceneData>(id_of(scene), "scene");
        d = s->device;
        auto accel = std::make_shared<Accel>();
        accel->device = d;
        accel->scene = s;
        try {
            cellrt::AccelConfig c = config ? cellrt::parse_accel_config(config)
                                           : cellrt::default_accel_config(where ? where : "cpu");
            if (where) c.device = where;
            accel->accelerator = cellrt::make_accelerator(s->triangles, c);
            accel->config = cellrt::format_accel_config(c);
            accel->where = c.device;
            const cellrt::AccelStats stats = accel->accelerator->stats();
            accel->build_seconds = stats.build_seconds;
            accel->memory_bytes = stats.memory_bytes;
        } catch (const cellrt::Error& e) {
            fail(CELLRT_ERROR_INVALID_CONFIG, "config '" + std::string(config ? config : "") + "'" +
                                                  (where ? " on '" + std::string(where) + "'" : "") + ": " + e.what());
        }
        id = table().add(std::move(accel));
    });
    return handle_of<cellrt_accel>(id);
}

}  // namespace

cellrt_accel cellrt_accel_new(cellrt_scene scene, const char* config) {
    return new_accel("cellrt_accel_new", scene, config, nullptr);
}

cellrt_accel cellrt_accel_new_on(cellrt_scene scene, const char* config, const char* where) {
    return new_accel("cellrt_accel_new_on", scene, config, where);
}

cellrt_error cellrt_accel_retain(cellrt_accel accel) {
    return count<Accel>("cellrt_accel_retain", id_of(accel), "accel", +1);
}

cellrt_error cellrt_accel_release(cellrt_accel accel) {
    return count<Accel>("cellrt_accel_release", id_of(accel), "accel", -1);
}

cellrt_error cellrt_accel_get_info(cellrt_accel accel, const char** config, const char** where, double* build_seconds,
                                   size_t* memory_bytes) {
    std::shared_ptr<Device> d;
    return guarded("cellrt_accel_get_info", d, [&] {
        const auto a = find<Accel>(id_of(accel), "accel");
        d = a->device;
        if (config) *config = a->config.c_str();
        if (where) *where = a->where.c_str();
        if (build_seconds) *build_seconds = a->build_seconds;
        if (memory_bytes) *memory_bytes = a->memory_bytes;
    });
}

cellrt_error cellrt_intersect(cellrt_accel accel, const cellrt_ray* rays, cellrt_hit* hits, size_t count) {
    std::shared_ptr<Device> d;
    return guarded("cellrt_intersect", d, [&] {
        const auto a = find<Accel>(id_of(accel), "accel");
        d = a->device;
        check_array(rays, "rays", count, sizeof(cellrt_ray));
        check_array(hits, "hits", count, sizeof(cellrt_hit));
        intersect_all(*a->accelerator, count, [&](std::size_t i) { return ray_of(rays[i]); },
                      [&](std::size_t i, const cellrt::Hit& h) { hits[i] = {h.t, h.prim, h.u, h.v}; });
    });
}

cellrt_error cellrt_intersect_soa(cellrt_accel accel, const cellrt_rays_soa* rays, const cellrt_hits_soa* hits,
                                  size_t count) {
    std::shared_ptr<Device> d;
    return guarded("cellrt_intersect_soa", d, [&] {
        const auto a = find<Accel>(id_of(accel), "accel");
        d = a->device;
        check_soa(rays, count);
        if (count == 0) return;
        check_array(hits, "hits", count, sizeof(float));
        check_array(hits->t, "hits->t", count, sizeof(float));
        check_array(hits->prim, "hits->prim", count, sizeof(uint32_t));
        const cellrt_hits_soa out = *hits;
        intersect_all(*a->accelerator, count, soa_loader(*rays), [&](std::size_t i, const cellrt::Hit& h) {
            out.t[i] = h.t;
            out.prim[i] = h.prim;
            if (out.u) out.u[i] = h.u;
            if (out.v) out.v[i] = h.v;
        });
    });
}

cellrt_error cellrt_occluded(cellrt_accel accel, const cellrt_ray* rays, uint8_t* occluded, size_t count) {
    std::shared_ptr<Device> d;
    return guarded("cellrt_occluded", d, [&] {
        const auto a = find<Accel>(id_of(accel), "accel");
        d = a->device;
        check_array(rays, "rays", count, sizeof(cellrt_ray));
        check_array(occluded, "occluded", count, sizeof(uint8_t));
        occluded_all(*a->accelerator, count, [&](std::size_t i) { return ray_of(rays[i]); }, occluded);
    });
}

cellrt_error cellrt_occluded_soa(cellrt_accel accel, const cellrt_rays_soa* rays, uint8_t* occluded, size_t count) {
    std::shared_ptr<Device> d;
    return guarded("cellrt_occluded_soa", d, [&] {
        const auto a = find<Accel>(id_of(accel), "accel");
        d = a->device;
        check_soa(rays, count);
        check_array(occluded, "occluded", count, sizeof(uint8_t));
        if (count == 0) return;
        occluded_all(*a->accelerator, count, soa_loader(*rays), occluded);
    });
}

const char* cellrt_error_name(cellrt_error code) {
    switch (code) {
        case CELLRT_SUCCESS: return "CELLRT_SUCCESS";
        case CELLRT_ERROR_UNKNOWN: return "CELLRT_ERROR_UNKNOWN";
        case CELLRT_ERROR_INVALID_ARGUMENT: return "CELLRT_ERROR_INVALID_ARGUMENT";
        case CELLRT_ERROR_INVALID_HANDLE: return "CELLRT_ERROR_INVALID_HANDLE";
        case CELLRT_ERROR_INVALID_CONFIG: return "CELLRT_ERROR_INVALID_CONFIG";
        case CELLRT_ERROR_OUT_OF_MEMORY: return "CELLRT_ERROR_OUT_OF_MEMORY";
        case CELLRT_ERROR_IO: return "CELLRT_ERROR_IO";
    }
    return "CELLRT_ERROR_UNRECOGNISED";
}

}  // extern "C"
