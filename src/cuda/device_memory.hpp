// The CUDA backend's memory modes (docs/GPU.md), chosen by the accelerator's -P parameters beside the
// tree's own: (a) `memory=global`, the tree read in global memory through L1 and L2; (b)
// `memory=shared`, the study's software caches in each block's shared memory (shared_cache.hpp), a
// node cache and a triangle cache of the layouts given. Read and validated on the host, before any
// device is needed, so a bad layout is refused in one line on any machine.
#pragma once

#include <cstddef>
#include <string>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"
#include "cuda/shared_cache.hpp"

namespace cellrt::detail {

struct DeviceMemoryConfig {
    bool shared = false;                      // mode (b)
    bool async = false;                       // mode (b): the study's asynchronous access (touch, then wait)
    SharedCacheLayout node_cache{128, 128, 1};  // the local-store model's default: the study's largest caches
    SharedCacheLayout triangle_cache{128, 128, 1};

    // Dynamic shared memory a block needs for both caches (mode (b)).
    std::size_t shared_bytes() const { return node_cache.bytes() + triangle_cache.bytes(); }
    // "global", or "shared: node cache 128x128, triangle cache 64x64x4, 35328 B a block" (", asynchronous
    // access" after it with `async`).
    std::string to_string() const;
};

// The parameters of the memory mode: memory, access, node_line, node_sets, node_ways, triangle_line, ...
const ParamTable& device_memory_params();

// The memory mode `config.params` asks for. Throws cellrt::Error in one line for a value out of
// range, a line or a set count that is not a power of two, or a cache parameter with memory=global.
DeviceMemoryConfig read_device_memory(const AccelConfig& config);

// `config` without the memory parameters: what the tree's own table validates.
AccelConfig without_device_memory(const AccelConfig& config);

// Throws cellrt::Error unless both caches of `memory` fit in `budget` bytes of shared memory a block
// (DeviceInfo::shared_memory_per_block), and a tree of `tree_bytes` bytes in the caches' address
// space (CacheAddressMap::end) has line numbers that fit their 32-bit tags.
void check_shared_memory(const DeviceMemoryConfig& memory, std::size_t budget, std::uint64_t tree_bytes);

}  // namespace cellrt::detail
