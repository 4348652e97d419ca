// The GPU side of the accelerator boundary (docs/GPU.md): what a CUDA device is present, batches of
// rays that stay in its memory between calls, and the accelerator that traces them there. A device
// accelerator is also an ordinary Accelerator: intersect()/occluded() over host batches copy the rays
// in, trace them on the device and copy the answers out, with the hits of every other path (the hit
// rule of ray.hpp; the device runs the host's own kernel source). make_device_accelerator
// (cellrt/accel.hpp) builds one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "cellrt/accelerator.hpp"
#include "cellrt/ray.hpp"
#include "cellrt/shading.hpp"
#include "cellrt/triangle.hpp"

namespace cellrt {

// The CUDA device this process would use (device 0), or why there is none. Never throws.
struct DeviceInfo {
    bool present = false;
    std::string name;             // e.g. "NVIDIA H200"
    int compute_major = 0, compute_minor = 0;
    int multiprocessors = 0;
    std::size_t memory_bytes = 0;
    std::size_t shared_memory_per_block = 0;  // the opt-in maximum, bytes
    std::string reason;           // when !present: no CUDA in this build, no driver, no device, ...
};
DeviceInfo cuda_device_info();

// A batch of rays and their answers resident in device memory (Aila & Laine's measurements keep rays
// on the device: a frame's rays are made and consumed there). Not copyable; one thread at a time.
class DeviceRayBatch {
public:
    // Room for `capacity` rays. Throws cellrt::Error when CUDA is absent or the allocation fails.
    explicit DeviceRayBatch(std::size_t capacity);
    ~DeviceRayBatch();
    DeviceRayBatch(const DeviceRayBatch&) = delete;
    DeviceRayBatch& operator=(const DeviceRayBatch&) = delete;

    // Copies `rays` in; size() becomes rays.size(). Throws cellrt::Error when it exceeds capacity().
    void upload(std::span<const Ray> rays);
    // Copy the answers of the last intersect/occluded out; spans of size() elements.
    void download_hits(std::span<Hit> hits) const;
    void download_occluded(std::span<std::uint8_t> occluded) const;

    std::size_t size() const { return size_; }
    std::size_t capacity() const { return capacity_; }
    // Device pointers, for a caller's own kernels (a frame made on the device).
    const Ray* device_rays() const { return rays_; }
    Hit* device_hits() const { return hits_; }
    std::uint8_t* device_occluded() const { return occluded_; }

private:
    std::size_t size_ = 0, capacity_ = 0;
    Ray* rays_ = nullptr;
    Hit* hits_ = nullptr;
    std::uint8_t* occluded_ = nullptr;
};

// What memory mode (b)'s software caches in shared memory counted (docs/GPU.md), as the local-store
// model's CacheStats counts: a read looks up every line its object overlaps. A lookup that finds the
// line is a hit, one that does not a miss (it fills the line, or, of those, `unfilled` ones read
// global memory because another thread of the block was filling the slot); a lookup that finds the
// line but sees it replaced while copying it out reads global memory too and counts as `torn`, not
// as a hit. Only concurrent threads make the last two: one thread a cache (the host's tests) never.
// Asynchronous access counts its touches apart, as the model does: `prefetches` started a line's
// fill, `touch_hits` found the line there.
struct DeviceCacheCounts {
    unsigned long long hits = 0, misses = 0, evictions = 0, torn = 0, unfilled = 0, prefetches = 0, touch_hits = 0;

    unsigned long long lookups() const { return hits + misses + torn; }
    DeviceCacheCounts& operator+=(const DeviceCacheCounts& o) {
        hits += o.hits; misses += o.misses; evictions += o.evictions; torn += o.torn; unfilled += o.unfilled;
        prefetches += o.prefetches; touch_hits += o.touch_hits;
        return *this;
    }
};

// The counts of every block of every launch so far, summed; all zero in memory mode (a).
struct DeviceCacheStats {
    DeviceCacheCounts node_cache, triangle_cache;  // nodes and leaf entries; triangles
    unsigned long long blocks = 0;                 // blocks launched with the caches
};

class DeviceAccelerator : public Accelerator {
public:
    // Trace a resident batch in place; return the kernel's own time in seconds (CUDA events: no
    // transfer, no launch set-up on the host). Counters as for intersect().
    virtual double intersect_resident(DeviceRayBatch& batch, TraversalCounters* counters = nullptr) const = 0;
    virtual double occluded_resident(DeviceRayBatch& batch, TraversalCounters* counters = nullptr) const = 0;
    // Memory mode (b)'s cache counts over every call so far, host and resident batches alike.
    virtual DeviceCacheStats cache_stats() const = 0;

    // The frame path (docs/GPU.md): the pixels [x0, x0 + width) x [y0, y0 + height) of the frame that
    // `frame` describes, made on the device, each pixel's rays made, traced and shaded by one thread
    // (shading.hpp's shade_pixel, the CPU renderer's colours bit for bit), into `pixels` (width x
    // height, row-major). `triangles` are the scene's, those the tree was built over (a hit names
    // one); they are copied in for the call, the pixels out. Adds the primary rays' work to `primary`
    // and every other ray's to `secondary`. Thread-safe as intersect() is. Throws cellrt::Error for
    // an empty window, a pixel count that does not match, a triangle count other than the tree's (the
    // triangles themselves are not compared), or a CUDA failure.
    struct FrameResult {
        double kernel_seconds = 0.0;  // the kernel's own time (CUDA events): no copies
        double seconds = 0.0;         // the whole call: triangles in, kernel, pixels out
    };
    virtual FrameResult render_frame(std::span<const Triangle> triangles, const FrameShading& frame, int x0, int y0,
                                     int width, int height, std::span<Vec3> pixels, TraversalCounters& primary,
                                     TraversalCounters& secondary) const = 0;
};

}  // namespace cellrt
