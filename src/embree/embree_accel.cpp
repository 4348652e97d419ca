#include "embree_accel.hpp"

#include <embree3/rtcore.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <mutex>
#include <numeric>

#include "cellrt/error.hpp"
#include "core/timer.hpp"
#include "kernel/param_reader.hpp"
#include "kernel/subtree.hpp"
#include "simd/isa.hpp"

namespace cellrt {
namespace {

const char* error_name(RTCError code) {
    switch (code) {
        case RTC_ERROR_NONE: return "no error";
        case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
        case RTC_ERROR_CANCELLED: return "cancelled";
        default: return "unknown error";
    }
}

// Collects what Embree reports through its error callback (which may run on Embree's build threads),
// so that the caller can throw it as a cellrt::Error once the Embree call has returned: an exception
// must not unwind through Embree's C interface, and Embree's default is only to set an error code.
class ErrorSink {
public:
    static void callback(void* self, RTCError code, const char* message) {
        auto& sink = *static_cast<ErrorSink*>(self);
        std::lock_guard lock(sink.mutex_);
        if (!sink.message_.empty()) return;  // the first error is the cause; later ones follow from it
        sink.message_ = std::string(error_name(code)) + (message ? std::string(": ") + message : std::string());
        sink.failed_.store(true, std::memory_order_release);
    }

    // Cheap enough for once per batch: one atomic load when nothing went wrong.
    void throw_if_failed(const char* during) const {
        if (!failed_.load(std::memory_order_acquire)) return;
        std::lock_guard lock(mutex_);
        throw Error(std::string("embree: ") + during + " failed: " + message_);
    }

private:
    mutable std::mutex mutex_;
    std::string message_;
    std::atomic<bool> failed_{false};
};

// Bytes Embree holds, from its memory monitor callback: positive before an allocation, negative
// after a release (rtcSetDeviceMemoryMonitorFunction). Called concurrently by build threads.
class MemoryTally {
public:
    static bool callback(void* self, ssize_t bytes, bool /*post*/) {
        auto& tally = *static_cast<MemoryTally*>(self);
        const std::int64_t now = tally.live_.fetch_add(bytes, std::memory_order_relaxed) + bytes;
        std::int64_t peak = tally.peak_.load(std::memory_order_relaxed);
        while (now > peak && !tally.peak_.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {}
        return true;  // never veto an allocation
    }
    std::size_t live() const { return static_cast<std::size_t>(std::max<std::int64_t>(live_.load(), 0)); }
    std::size_t peak() const { return static_cast<std::size_t>(std::max<std::int64_t>(peak_.load(), 0)); }

private:
    std::atomic<std::int64_t> live_{0};
    std::atomic<std::int64_t> peak_{0};
};

struct ReleaseDevice {
    void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
};
struct ReleaseScene {
    void operator()(RTCScene s) const { rtcReleaseScene(s); }
};
using DeviceHandle = std::unique_ptr<RTCDeviceTy, ReleaseDevice>;
using SceneHandle = std::unique_ptr<RTCSceneTy, ReleaseScene>;

// Embree's ray structures keep each field as a scalar (RTCRay) or as one array lane per ray
// (RTCRay4/8/16); lane() lets one function fill and read both.
template <typename T>
T& lane(T& field, int) {
    return field;
}
template <typename T, std::size_t W>
T& lane(T (&field)[W], int k) {
    return field[k];
}

template <typename EmbreeRay>
void store_ray(EmbreeRay& er, int k, const Ray& r) {
    lane(er.org_x, k) = r.org.x;
    lane(er.org_y, k) = r.org.y;
    lane(er.org_z, k) = r.org.z;
    lane(er.tnear, k) = r.tnear;
    // The direction every path of cellrt traces (ray.hpp: subnormal components as zeros), so that
    // Embree answers the same ray.
    const Vec3 d = traced_direction(r);
    lane(er.dir_x, k) = d.x;
    lane(er.dir_y, k) = d.y;
    lane(er.dir_z, k) = d.z;
    lane(er.time, k) = 0.f;
    lane(er.tfar, k) = r.tfar;
    lane(er.mask, k) = ~0u;
    lane(er.id, k) = 0;
    lane(er.flags, k) = 0;
}

// A closest-hit query: the ray, and a hit record that says "nothing yet".
template <typename EmbreeRayHit>
void store_query(EmbreeRayHit& rh, int k, const Ray& r) {
    store_ray(rh.ray, k, r);
    lane(rh.hit.geomID, k) = RTC_INVALID_GEOMETRY_ID;
    lane(rh.hit.instID[0], k) = RTC_INVALID_GEOMETRY_ID;
}

// Embree's u, v weigh v1 and v2 (point = (1-u-v) v0 + u v1 + v v2), as cellrt's do; primID is the
// cellrt triangle index because the index buffer is 0, 1, ..., 3N-1.
template <typename EmbreeRayHit>
Hit load_hit(const EmbreeRayHit& rh, int k) {
    if (lane(rh.hit.geomID, k) == RTC_INVALID_GEOMETRY_ID) return Hit{};
    return Hit{lane(rh.ray.tfar, k), lane(rh.hit.primID, k), lane(rh.hit.u, k), lane(rh.hit.v, k)};
}

// rtcOccluded* marks an occluded ray by setting its tfar to -inf.
template <typename EmbreeRay>
bool load_occluded(const EmbreeRay& er, int k) {
    return lane(er.tfar, k) == -std::numeric_limits<float>::infinity();
}

// Embree's domain (rtcore_ray.h, RTCRay(3)): a ray segment within [0, inf], and origin and direction
// components of magnitude at most FLT_LARGE; its kernels assert both, and Debian's build keeps the
// assertions, so a ray outside would abort the program.
constexpr float kEmbreeLargest = 1.844e18f;

bool within_embree_range(const Vec3& v) {
    return std::fabs(v.x) <= kEmbreeLargest && std::fabs(v.y) <= kEmbreeLargest && std::fabs(v.z) <= kEmbreeLargest;
}

// Whether ray `index` of a batch goes to Embree: false for rays that hit nothing by cellrt's rule
// (is_valid), an error for valid rays Embree cannot take (negative tnear, huge components): Embree
// cannot answer them under cellrt's rule, and a wrong answer must not pass silently.
bool admit(const Ray& r, std::size_t index) {
    if (!is_valid(r)) return false;
    if (r.tnear >= 0.f && within_embree_range(r.org) && within_embree_range(r.dir)) return true;
    char buf[256];
    if (!(r.tnear >= 0.f))
        std::snprintf(buf, sizeof buf, "embree: ray %zu of the batch has tnear %g; Embree needs tnear >= 0", index,
                      r.tnear);
    else
        std::snprintf(buf, sizeof buf, "embree: ray %zu of the batch has an origin or direction component beyond "
                      "+-%g, outside Embree's range", index, kEmbreeLargest);
    throw Error(buf);
}

// Lanes of a partial last chunk, and lanes of invalid rays, are switched off in the valid mask; they
// still get a harmless finite ray so that Embree's SIMD code never computes on stale NaNs or
// denormals in them.
const Ray kIdleLane{Vec3{}, 0.f, Vec3{0.f, 0.f, 1.f}, 0.f};

template <int W>
struct Packet;
template <>
struct Packet<4> {
    using RayHit = RTCRayHit4;
    using Rays = RTCRay4;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect4(v, s, c, rh); }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, RTCRay4* r) { rtcOccluded4(v, s, c, r); }
};
template <>
struct Packet<8> {
    using RayHit = RTCRayHit8;
    using Rays = RTCRay8;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect8(v, s, c, rh); }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, RTCRay8* r) { rtcOccluded8(v, s, c, r); }
};
template <>
struct Packet<16> {
    using RayHit = RTCRayHit16;
    using Rays = RTCRay16;
    static void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RayHit* rh) { rtcIntersect16(v, s, c, rh); }
    static void occluded(const int* v, RTCScene s, RTCIntersectContext* c, RTCRay16* r) { rtcOccluded16(v, s, c, r); }
};

// The valid mask of rtcIntersect4/8/16 must be aligned like the packet itself (16, 32, 64 bytes).
template <int W>
struct alignas(W * sizeof(int)) ValidMask {
    int lanes[W];
};

// The packet widths of embree_traversals() (1: one ray per call).
constexpr int kTraversalWidths[] = {1, 4, 8, 16};

RTCBuildQuality parse_quality(const std::string& name) {
    if (name == "low") return RTC_BUILD_QUALITY_LOW;
    if (name == "high") return RTC_BUILD_QUALITY_HIGH;
    return RTC_BUILD_QUALITY_MEDIUM;
}

struct EmbreeOptions {
    std::string quality;
    bool robust;
    bool compact;
    std::string traversal;
    int width;  // packet width of the traversal
    unsigned threads;
};

class EmbreeAccel final : public Accelerator {
public:
    EmbreeAccel(std::span<const Triangle> triangles, const EmbreeOptions& options) : options_(options) {
        const Timer setup;
        create_device();
        check_device_properties();
        create_scene(triangles);
        setup_seconds_ = setup.seconds();
        const Timer build;
        commit_scene();
        build_seconds_ = build.seconds();
        build_cpu_seconds_ = build.cpu_seconds();
    }

    AccelStats stats() const override {
        AccelStats s;
        s.name = "embree";
        s.traversal = options_.traversal;
        s.build_seconds = build_seconds_;
        s.build_cpu_seconds = build_cpu_seconds_;
        s.memory_bytes = memory_.live();
        s.triangles = triangle_count_;
        s.counts_work = false;
        s.settings = {{"quality", options_.quality},
                      {"robust", options_.robust ? "true" : "false"},
                      {"compact", options_.compact ? "true" : "false"},
                      {"threads", options_.threads == 0 ? "all" : std::to_string(options_.threads)},
                      {"native packets", native_packets_},
                      {"setup seconds", std::to_string(setup_seconds_)},
                      {"peak bytes", std::to_string(memory_.peak())},
                      {"counters", "rays only (Embree reports no node or triangle counts)"},
                      {"library", "Embree " RTC_VERSION_STRING}};
        return s;
    }

    bool refuses_rays() const override { return true; }
    void check_rays(std::span<const Ray> rays, std::size_t first) const override {
        for (std::size_t i = 0; i < rays.size(); ++i) static_cast<void>(admit(rays[i], first + i));
    }

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        switch (options_.width) {
            case 4: intersect_packets<4>(rays, hits); break;
            case 8: intersect_packets<8>(rays, hits); break;
            case 16: intersect_packets<16>(rays, hits); break;
            default: intersect_single(rays, hits); break;
        }
        errors_.throw_if_failed("intersect");
        if (counters) counters->rays += rays.size();
    }

    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        switch (options_.width) {
            case 4: occluded_packets<4>(rays, occluded); break;
            case 8: occluded_packets<8>(rays, occluded); break;
            case 16: occluded_packets<16>(rays, occluded); break;
            default: occluded_single(rays, occluded); break;
        }
        errors_.throw_if_failed("occluded");
        if (counters) counters->rays += rays.size();
    }

    void create_device() {
        // Configuration files (.embree3 beside the program or in $HOME) are ignored, so that a
        // benchmark's yardstick does not depend on the user's home folder.
        device_.reset(rtcNewDevice("ignore_config_files=1,verbose=0"));
        if (!device_)
            throw Error(std::string("embree: cannot create a device: ") + error_name(rtcGetDeviceError(nullptr)));
        rtcSetDeviceErrorFunction(device_.get(), &ErrorSink::callback, &errors_);
        rtcSetDeviceMemoryMonitorFunction(device_.get(), &MemoryTally::callback, &memory_);
    }

    void check_device_properties() {
        RTCDevice d = device_.get();
        if (rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED) != 1)
            throw Error("embree: this Embree library was built without triangle geometry");
        if (rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED) != 0)
            throw Error("embree: this Embree library was built with back-face culling; cellrt's hit rule counts "
                        "both sides of a triangle");
        const std::pair<RTCDeviceProperty, int> widths[] = {{RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED, 4},
                                                            {RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED, 8},
                                                            {RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED, 16}};
        bool wanted_is_native = options_.width == 1;
        for (const auto& [property, width] : widths) {
            if (rtcGetDeviceProperty(d, property) != 1) continue;
            if (!native_packets_.empty()) native_packets_ += ',';
            native_packets_ += std::to_string(width);
            wanted_is_native = wanted_is_native || width == options_.width;
        }
        if (native_packets_.empty()) native_packets_ = "none";
        if (!wanted_is_native)
            throw Error("embree traversal '" + options_.traversal + "' needs native " + std::to_string(options_.width) +
                        "-wide ray packets, which this CPU or Embree library does not offer (native widths: " +
                        native_packets_ + "; choose traversal single or a native width)");
        errors_.throw_if_failed("device set-up");
    }

    // One triangle mesh with 3 vertices per cellrt triangle and indices 0..3N-1, so that Embree's
    // primID is the cellrt triangle index. Zero-area triangles stay in (Embree never hits them, as
    // the hit rule says); both buffers are Embree's own, which pads them as its SIMD loads need.
    void create_scene(std::span<const Triangle> triangles) {
        static_assert(sizeof(Triangle) == 9 * sizeof(float), "Triangle must be three packed float vertices");
        if (triangles.size() > std::numeric_limits<unsigned>::max() / 3)
            throw Error("embree: " + std::to_string(triangles.size()) + " triangles exceed Embree's 32-bit indices");
        for (std::size_t i = 0; i < triangles.size(); ++i) {
            const Triangle& t = triangles[i];
            if (!within_embree_range(t.v0) || !within_embree_range(t.v1) || !within_embree_range(t.v2))
                throw Error("embree: triangle " + std::to_string(i) + " has a coordinate beyond +-1.844e18 "
                            "(or not finite), which Embree would silently drop");
        }
        triangle_count_ = triangles.size();
        const RTCBuildQuality quality = parse_quality(options_.quality);
        scene_.reset(rtcNewScene(device_.get()));
        errors_.throw_if_failed("scene creation");
        int flags = RTC_SCENE_FLAG_NONE;
        if (options_.robust) flags |= RTC_SCENE_FLAG_ROBUST;
        if (options_.compact) flags |= RTC_SCENE_FLAG_COMPACT;
        rtcSetSceneFlags(scene_.get(), static_cast<RTCSceneFlags>(flags));
        rtcSetSceneBuildQuality(scene_.get(), quality);
        if (!triangles.empty()) {
            RTCGeometry geometry = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
            errors_.throw_if_failed("geometry creation");
            rtcSetGeometryBuildQuality(geometry, quality);
            const std::size_t n = triangles.size();
            void* vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                     3 * sizeof(float), 3 * n);
            auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
                geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
            if (vertices && indices) {
                std::memcpy(vertices, triangles.data(), triangles.size_bytes());
                std::iota(indices, indices + 3 * n, 0u);
                rtcCommitGeometry(geometry);
                rtcAttachGeometry(scene_.get(), geometry);
            }
            rtcReleaseGeometry(geometry);  // the scene holds its own reference
        }
        errors_.throw_if_failed("geometry set-up");
    }

    // The build runs in a TBB arena of AccelConfig::threads slots. Embree's own `threads=N` device
    // setting would instead cap TBB's parallelism for the whole process (a tbb::global_control) for as
    // long as the device lives, and so also slow down whatever the caller builds or traces beside it.
    void commit_scene() {
        if (options_.threads == 0) {
            rtcCommitScene(scene_.get());
        } else {
            tbb::task_arena arena(detail::build_concurrency(options_.threads));
            arena.execute([&] { rtcCommitScene(scene_.get()); });
        }
        errors_.throw_if_failed("build (rtcCommitScene)");
    }

    void intersect_single(std::span<const Ray> rays, std::span<Hit> hits) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if (!admit(rays[i], i)) {
                hits[i] = Hit{};
                continue;
            }
            RTCRayHit rh;
            store_query(rh, 0, rays[i]);
            rtcIntersect1(scene_.get(), &context, &rh);
            hits[i] = load_hit(rh, 0);
        }
    }

    void occluded_single(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            occluded[i] = 0;
            if (!admit(rays[i], i)) continue;
            RTCRay er;
            store_ray(er, 0, rays[i]);
            rtcOccluded1(scene_.get(), &context, &er);
            occluded[i] = load_occluded(er, 0);
        }
    }

    // Fills the lanes of chunk [base, base + W) and its valid mask; returns how many lanes are rays.
    template <int W, typename EmbreeRays, typename Store>
    static int fill_chunk(std::span<const Ray> rays, std::size_t base, ValidMask<W>& valid, EmbreeRays& packet,
                          Store store) {
        const int used = static_cast<int>(std::min<std::size_t>(W, rays.size() - base));
        for (int k = 0; k < W; ++k) {
            const bool on = k < used && admit(rays[base + k], base + k);
            valid.lanes[k] = on ? -1 : 0;
            store(packet, k, on ? rays[base + k] : kIdleLane);
        }
        return used;
    }

    template <int W>
    void intersect_packets(std::span<const Ray> rays, std::span<Hit> hits) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (std::size_t base = 0; base < rays.size(); base += W) {
            ValidMask<W> valid;
            typename Packet<W>::RayHit rh;  // aligned to its width by RTC_ALIGN
            const int used = fill_chunk<W>(rays, base, valid, rh, [](auto& p, int k, const Ray& r) {
                store_query(p, k, r);
            });
            Packet<W>::intersect(valid.lanes, scene_.get(), &context, &rh);
            for (int k = 0; k < used; ++k) hits[base + k] = valid.lanes[k] ? load_hit(rh, k) : Hit{};
        }
    }

    template <int W>
    void occluded_packets(std::span<const Ray> rays, std::span<std::uint8_t> occluded) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (std::size_t base = 0; base < rays.size(); base += W) {
            ValidMask<W> valid;
            typename Packet<W>::Rays packet;
            const int used = fill_chunk<W>(rays, base, valid, packet, [](auto& p, int k, const Ray& r) {
                store_ray(p, k, r);
            });
            Packet<W>::occluded(valid.lanes, scene_.get(), &context, &packet);
            for (int k = 0; k < used; ++k) occluded[base + k] = valid.lanes[k] && load_occluded(packet, k);
        }
    }

    EmbreeOptions options_;
    std::string native_packets_;
    std::size_t triangle_count_ = 0;
    double setup_seconds_ = 0.0;
    double build_seconds_ = 0.0, build_cpu_seconds_ = 0.0;
    // Declared before the handles: Embree calls both back until the device is released.
    ErrorSink errors_;
    MemoryTally memory_;
    DeviceHandle device_;
    SceneHandle scene_;
};

}  // namespace

const ParamTable& embree_params() {
    using enum ParamType;
    static const ParamTable table{
        {"quality", choice, "medium", 0, 0, {"low", "medium", "high"},
         "Embree's RTC_BUILD_QUALITY_*: Morton build, SAH build, SAH build with spatial splits (Embree's default: "
         "medium; Embree makes spatial splits only with robust=false and compact=false, and builds `high` as "
         "`medium` otherwise)"},
        {"robust", boolean, "true", 0, 0, {},
         "RTC_SCENE_FLAG_ROBUST: conservative box tests and Embree's watertight triangle test, the closest Embree comes "
         "to cellrt's hit rule"},
        {"compact", boolean, "false", 0, 0, {},
         "RTC_SCENE_FLAG_COMPACT: triangles stored as vertex indices, less memory, slower queries"},
    };
    return table;
}

// A function's static, for the reason bvh_traversals() gives (bvh_accel.cpp).
const std::vector<std::string>& embree_traversals() {
    static const std::vector<std::string> names{"single", "packet4", "packet8", "packet16"};
    return names;
}

std::unique_ptr<Accelerator> make_embree(std::span<const Triangle> triangles, const AccelConfig& config) {
    // Embree picks its own instruction set; a SIMD set named for it is still checked, as for every kind.
    if (config.simd != "off") static_cast<void>(detail::parse_isa(config.simd));
    detail::ParamReader params(embree_params(), config, "embree");
    EmbreeOptions options;
    options.quality = params.choice("quality");
    options.robust = params.boolean("robust");
    options.compact = params.boolean("compact");
    params.finish();
    const std::vector<std::string>& traversals = embree_traversals();
    options.traversal = detail::choose_traversal(traversals, config.traversal, "embree");
    options.width = kTraversalWidths[std::find(traversals.begin(), traversals.end(), options.traversal) -
                                     traversals.begin()];
    options.threads = config.threads;
    return std::make_unique<EmbreeAccel>(triangles, options);
}

}  // namespace cellrt
