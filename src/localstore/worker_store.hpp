// One worker's local store in the model: its node and triangle caches, its DMA engine and its clock.
// Every byte a kernel reads comes out of a cache line that a (modelled) DMA copied in from main memory;
// the clock advances by the work done and by the waits for transfers (cost_model.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "dma_engine.hpp"
#include "local_store.hpp"
#include "main_memory.hpp"
#include "software_cache.hpp"

namespace cellrt::detail {

class WorkerStore {
public:
    WorkerStore(const LocalStoreConfig& config, const MainMemory& memory);

    SoftwareCache node_cache, triangle_cache;

    // Reads `size` bytes at model address `address` through `cache` into `out`, line by line: a line
    // found is a hit, a missing one is transferred (a miss); either way the worker waits until the
    // line is there. `lookups` tag checks per line: 2 for an asynchronous wait with its re-touch.
    void read(SoftwareCache& cache, std::uint64_t address, std::uint32_t size, void* out, std::uint32_t lookups = 1) {
        read_lines(cache, address, size, out, lookups, false);
    }

    // The asynchronous touch: starts the transfer of every line of [address, address + size) that
    // `cache` lacks, without waiting, and remembers for this ray the slot each line went to.
    void touch(SoftwareCache& cache, std::uint64_t address, std::uint32_t size);

    // A wait without its re-touch: a line touched in this ray and evicted since is read from the slot
    // its touch chose, whatever that slot holds now (a stale wait); other lines are read as by read().
    // Returns true when some line was stale, so `out` holds another line's bytes.
    bool wait_unchecked(SoftwareCache& cache, std::uint64_t address, std::uint32_t size, void* out) {
        return read_lines(cache, address, size, out, 1, true);
    }

    void work(std::uint64_t cycles) { now_ += cycles; }
    void begin_ray() {
        ++ray_serial_;
        now_ += cost_.ray_setup;
    }
    // A batch of `rays` rays comes in by DMA before its traversals (the worker waits for it); its
    // results go out by DMA behind it (the worker does not wait).
    void load_batch(std::uint32_t rays, std::uint32_t bytes);
    void store_results(std::uint32_t bytes);

    std::uint64_t cycles() const { return now_; }
    std::uint64_t stall_cycles() const { return stall_; }
    std::uint64_t rays() const { return rays_; }
    std::uint64_t batches() const { return batches_; }

private:
    // Where this ray's touches placed their lines: the pointer a kernel on the Cell keeps from its
    // touch to its wait. A small hash table keyed by line address; a record overwritten by a colliding
    // line only makes a later stale wait go unnoticed (it is then served correctly).
    struct TouchRecord {
        std::uint64_t line = ~std::uint64_t(0);
        std::uint64_t ray = 0;
        std::uint32_t slot = 0;
    };

    // read() and wait_unchecked(): with `trust_touches`, a missing line touched in this ray is read
    // from its touch's slot instead of being transferred.
    bool read_lines(SoftwareCache& cache, std::uint64_t address, std::uint32_t size, void* out, std::uint32_t lookups,
                    bool trust_touches);
    std::uint32_t fill(SoftwareCache& cache, std::uint64_t line);
    // Issues a transfer and returns when its data will be there; a full DMA queue stalls the worker.
    std::uint64_t issue(std::uint32_t bytes) {
        const std::uint64_t before = now_;
        const std::uint64_t ready = dma_.issue(now_, bytes);
        stall_ += now_ - before;
        return ready;
    }
    void wait_until(std::uint64_t ready) {
        if (ready > now_) {
            stall_ += ready - now_;
            now_ = ready;
        }
    }
    TouchRecord& record(const SoftwareCache& cache, std::uint64_t line) {
        return touched_[(line / cache.line_bytes()) & (touched_.size() - 1)];
    }
    bool touched_in_this_ray(const SoftwareCache& cache, std::uint64_t line) {
        if (touched_.empty()) return false;
        const TouchRecord& r = record(cache, line);
        return r.line == line && r.ray == ray_serial_;
    }

    CostModel cost_;
    const MainMemory* memory_;
    DmaEngine dma_;
    std::vector<TouchRecord> touched_;  // only for asynchronous access without re-touch
    std::uint64_t now_ = 0, stall_ = 0, rays_ = 0, batches_ = 0;
    std::uint64_t ray_serial_ = 0;  // rays traversed so far: touch records are valid within one
};

}  // namespace cellrt::detail
