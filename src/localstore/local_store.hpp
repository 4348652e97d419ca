// The study's memory system of a worker core (Hapala, sections 4.3 and 5.2), as a model the very same
// traversal kernels run through: each worker has a local store with a byte budget, holding a node
// cache, a triangle cache, the traversal stack and a batch of rays and results. The kernels read only
// what the software caches copied in from main memory, synchronously (a read stalls until its line is
// there) or asynchronously (touch the children when reading an inner node, wait when going to one),
// and a cost model turns the work and the transfers into modelled cycles (cost_model.hpp). Hits are
// exactly those of direct memory; docs/LOCALSTORE.md describes the model and the study's experiments.
//
// This header uses only the public headers, so the cellrt program can include it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cache_layout.hpp"
#include "cache_stats.hpp"
#include "cellrt/accelerator.hpp"
#include "cost_model.hpp"

namespace cellrt {

enum class CacheAccess { sync, async };

CacheAccess parse_cache_access(const std::string& option, const std::string& text);  // "sync" | "async"
const char* to_string(CacheAccess access);

struct LocalStoreConfig {
    std::size_t budget_bytes = 256 * 1024;  // the SPE's local store
    CacheLayout node_cache{128, 128, 1};    // 16 KiB each: the study's largest caches
    CacheLayout triangle_cache{128, 128, 1};
    CacheAccess access = CacheAccess::sync;
    // Asynchronous access only: touch a node's line again right before waiting for it. Without the
    // re-touch a wait trusts the slot its touch chose even when the line was evicted since (the
    // study's artifact): the kernel then reads another line's bytes.
    bool retouch = true;
    // Rays the local store holds at once, with their results: one batch. A call with more rays is
    // traced batch by batch. `render` and `cache-study` make it the P * P rays of their P x P packet.
    std::size_t batch_rays = 256;
    CostModel cost;
};

// One allocation of the local store.
struct LocalStoreAllocation {
    std::string what;
    std::size_t bytes;
};

// The largest budget the model takes: 4 GiB - 1, as its transfers count bytes in 32 bits.
inline constexpr std::size_t kMaxLocalStoreBytes = 0xffff'ffff;

// The most rays a batch may hold in a local store of `budget_bytes`, each with its result, before
// anything else is allocated.
std::size_t max_batch_rays(std::size_t budget_bytes);

// The allocations of `config` with a traversal stack of `stack_bytes`. Throws cellrt::Error when a
// layout is invalid, the budget is over kMaxLocalStoreBytes or the allocations exceed it, saying by
// how many bytes.
std::vector<LocalStoreAllocation> allocate_local_store(const LocalStoreConfig& config, std::size_t stack_bytes);

// Bytes of directory (tag and replacement state) the local store keeps per cache line.
inline constexpr std::size_t kDirectoryBytesPerLine = 8;

struct LocalStoreStats {
    CacheStats node_cache, triangle_cache;
    std::uint64_t rays = 0;          // rays traced through the model (primary and secondary)
    // Batches loaded into a local store (WorkerStore::load_batch); a renderer's packet is two, its
    // primary rays and its shadow rays (one when none of its primary rays hit).
    std::uint64_t batches = 0;
    std::uint64_t cycles = 0;        // modelled cycles, summed over the workers
    std::uint64_t stall_cycles = 0;  // of which the workers waited for transfers
    std::uint64_t frame_cycles = 0;  // the busiest worker's cycles: the run's modelled duration
    unsigned workers = 0;

    double cycles_per_ray() const { return rays ? static_cast<double>(cycles) / static_cast<double>(rays) : 0.0; }
};

// A tree whose traversals run through the local-store model (model_accelerator.hpp). intersect() and occluded() may
// be called concurrently: each calling thread is a worker with a local store of its own, kept from one
// call to the next as a worker keeps its caches from one packet to the next.
class LocalStoreAccelerator : public Accelerator {
public:
    virtual const LocalStoreConfig& local_store_config() const = 0;
    virtual std::vector<LocalStoreAllocation> local_store_allocations() const = 0;
    // Summed over every worker so far; call it between traces, not during one. With one worker the
    // figures are reproducible; with several they depend on which worker traced which packet.
    virtual LocalStoreStats local_store_stats() const = 0;
    // The same built structure through new, empty local stores of another configuration (for sweeps).
    virtual std::unique_ptr<LocalStoreAccelerator> with_local_store(const LocalStoreConfig& config,
                                                                    const std::string& traversal) const = 0;
};

// Built by make_local_store_accelerator() (accel/local_store_registry.hpp) for every tree the registry lists.

}  // namespace cellrt
