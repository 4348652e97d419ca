#include "worker_store.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

namespace cellrt::detail {
namespace {

// Copies the part of [address, address + size) that lies in the line starting at `line`.
void copy_piece(const std::byte* line_bytes, std::uint64_t line, std::uint32_t line_size, std::uint64_t address,
                std::uint32_t size, std::byte* out) {
    const std::uint64_t from = std::max(address, line), to = std::min(address + size, line + line_size);
    std::memcpy(out + (from - address), line_bytes + (from - line), static_cast<std::size_t>(to - from));
}

}  // namespace

WorkerStore::WorkerStore(const LocalStoreConfig& config, const MainMemory& memory)
    : node_cache(config.node_cache), triangle_cache(config.triangle_cache), cost_(config.cost), memory_(&memory),
      dma_(config.cost) {
    if (config.access == CacheAccess::async && !config.retouch)
        touched_.resize(std::bit_ceil(std::max<std::size_t>(1024, 2 * config.node_cache.lines())));
}

std::uint32_t WorkerStore::fill(SoftwareCache& cache, std::uint64_t line) {
    now_ += cost_.miss_handling;
    const std::uint32_t slot = cache.place(line);
    memory_->copy(line, cache.line_bytes(), cache.bytes(slot));
    cache.ready(slot) = issue(cache.line_bytes());
    cache.stats.bytes += cache.line_bytes();
    return slot;
}

bool WorkerStore::read_lines(SoftwareCache& cache, std::uint64_t address, std::uint32_t size, void* out,
                             std::uint32_t lookups, bool trust_touches) {
    now_ += cost_.ls_access;
    bool stale = false;
    for (std::uint64_t line = cache.line_of(address); line < address + size; line += cache.line_bytes()) {
        now_ += lookups * cost_.cache_lookup;
        std::uint32_t slot = cache.find(line);
        if (slot != SoftwareCache::kAbsent) {
            ++cache.stats.hits;
            cache.use(slot);
        } else if (trust_touches && touched_in_this_ray(cache, line)) {
            ++cache.stats.stale_waits;
            slot = record(cache, line).slot;
            stale = true;
        } else {
            ++cache.stats.misses;
            slot = fill(cache, line);
        }
        wait_until(cache.ready(slot));
        copy_piece(cache.bytes(slot), line, cache.line_bytes(), address, size, static_cast<std::byte*>(out));
    }
    return stale;
}

void WorkerStore::touch(SoftwareCache& cache, std::uint64_t address, std::uint32_t size) {
    for (std::uint64_t line = cache.line_of(address); line < address + size; line += cache.line_bytes()) {
        now_ += cost_.cache_lookup;
        std::uint32_t slot = cache.find(line);
        if (slot == SoftwareCache::kAbsent) {
            ++cache.stats.prefetches;
            slot = fill(cache, line);
        } else {
            ++cache.stats.touch_hits;
            cache.use(slot);
        }
        if (!touched_.empty()) record(cache, line) = {line, ray_serial_, slot};
    }
}

void WorkerStore::load_batch(std::uint32_t rays, std::uint32_t bytes) {
    ++batches_;
    rays_ += rays;
    wait_until(issue(bytes));
}

void WorkerStore::store_results(std::uint32_t bytes) { issue(bytes); }

}  // namespace cellrt::detail
