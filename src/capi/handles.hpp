// The objects behind the C API's handles (include/cellrt/cellrt.h) and the table that maps handles to
// them. A handle is a serial number, never reused, so a released or made-up handle is found missing
// instead of being read as freed memory (Embree's handles are pointers; a double release there is
// undefined). The table holds one shared_ptr per live handle; a call copies it under a shared lock, so
// a handle released by another thread meanwhile stays alive until that call returns.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <unordered_map>
#include <variant>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/cellrt.h"

namespace cellrt::capi {

struct Device {
    std::uint64_t id = 0;
    std::mutex mutex;  // guards the error function
    cellrt_error_function error_function = nullptr;
    void* error_user = nullptr;
};

struct SceneData {
    std::shared_ptr<Device> device;
    std::vector<Triangle> triangles;  // read by the kd-tree and brute force on every call (accel.hpp)
};

struct Accel {
    std::shared_ptr<Device> device;
    std::shared_ptr<const SceneData> scene;  // kept as long as the structure that may read it
    std::unique_ptr<Accelerator> accelerator;
    // What cellrt_accel_get_info reports, fixed at the build (so that reading it takes no lock).
    std::string config, where;
    double build_seconds = 0.0;
    std::size_t memory_bytes = 0;
};

using Object = std::variant<std::shared_ptr<Device>, std::shared_ptr<SceneData>, std::shared_ptr<Accel>>;

class HandleTable {
public:
    // A new handle with a reference count of 1 (a device learns its id before anyone can find it).
    std::uint64_t add(Object object) {
        std::unique_lock lock(mutex_);
        const std::uint64_t id = next_++;
        if (auto* device = std::get_if<std::shared_ptr<Device>>(&object)) (*device)->id = id;
        entries_.emplace(id, Entry{std::move(object), 1});
        return id;
    }

    // The object of handle `id` when it is live and of kind T, else null.
    template <class T>
    std::shared_ptr<T> find(std::uint64_t id) const {
        std::shared_lock lock(mutex_);
        const auto it = entries_.find(id);
        if (it == entries_.end()) return nullptr;
        const auto* p = std::get_if<std::shared_ptr<T>>(&it->second.object);
        return p ? *p : nullptr;
    }

    // Adds `delta` (+1 or -1) to the count of a live handle of kind T, removing it at zero; false when
    // there is no such handle. The object removed is returned so that it dies outside the lock.
    template <class T>
    bool count(std::uint64_t id, int delta, Object& removed) {
        std::unique_lock lock(mutex_);
        const auto it = entries_.find(id);
        if (it == entries_.end() || !std::holds_alternative<std::shared_ptr<T>>(it->second.object)) return false;
        it->second.references += delta;
        if (it->second.references == 0) {
            removed = std::move(it->second.object);
            entries_.erase(it);
        }
        return true;
    }

private:
    struct Entry {
        Object object;
        std::uint64_t references;
    };
    mutable std::shared_mutex mutex_;
    std::unordered_map<std::uint64_t, Entry> entries_;
    std::uint64_t next_ = 1;  // 0 is NULL
};

}  // namespace cellrt::capi
