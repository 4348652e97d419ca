// What one thread of the CUDA backend runs for one ray, compiled for the host as well (CELLRT_HD) and
// tested there against brute force on every scene (tests/test_device_code.cpp): a descriptor's kernel
// (the function objects its with_kernel() hands out: kernel/stack_traversal.hpp, TA_rec) over a
// TreeView in direct memory or through a memory policy (mode (b)'s caches, shared_cache.hpp), through the per-ray queries of kernel/traversal.hpp that the host's batch
// loops run too. The stack is the kernel's own array, in each thread's local memory.
#pragma once

#include <cstdint>

#include "cellrt/host_device.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {

// A descriptor's kernel bound to a tree view and a memory policy: kernel(ray, query, counters), as the
// per-ray queries take it. Direct memory (mode (a)) or the block's shared-memory caches (mode (b),
// shared_cache.hpp): the same kernel either way.
template <class Traits, class Kernel, class Memory>
struct ViewKernel {
    const TreeView<Traits>& view;
    Memory& mem;

    template <class Query, class Counters>
    CELLRT_HD bool operator()(const TraversalRay& r, Query& q, Counters& c) const {
        return Kernel{}(view, mem, r, q, c);
    }
};

// One ray's work counts, kept in registers and added to the batch's sums once per ray.
struct RayCounters {
    std::uint32_t nodes = 0, leaves = 0, triangles = 0;
    CELLRT_HD void node() { ++nodes; }
    CELLRT_HD void leaf() { ++leaves; }
    CELLRT_HD void triangle() { ++triangles; }
};

template <class Traits, class Kernel, class Memory>
CELLRT_HD Hit trace_closest(const TreeView<Traits>& view, Memory& mem, const Ray& ray, RayCounters& c) {
    return closest_hit(view.bounds, ray, c, ViewKernel<Traits, Kernel, Memory>{view, mem});
}

template <class Traits, class Kernel, class Memory>
CELLRT_HD bool trace_any(const TreeView<Traits>& view, Memory& mem, const Ray& ray, RayCounters& c) {
    return any_hit(view.bounds, ray, c, ViewKernel<Traits, Kernel, Memory>{view, mem});
}

// In direct memory: the tree's arrays read where they lie.
template <class Traits, class Kernel>
CELLRT_HD Hit trace_closest(const TreeView<Traits>& view, const Ray& ray, RayCounters& c) {
    auto mem = view.memory();
    return trace_closest<Traits, Kernel>(view, mem, ray, c);
}

template <class Traits, class Kernel>
CELLRT_HD bool trace_any(const TreeView<Traits>& view, const Ray& ray, RayCounters& c) {
    auto mem = view.memory();
    return trace_any<Traits, Kernel>(view, mem, ray, c);
}

}  // namespace cellrt::detail
