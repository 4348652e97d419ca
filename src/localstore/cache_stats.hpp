// What one software cache of the local-store model counted. A read looks up every line its object
// overlaps: a hit finds the line in the cache (arrived, or still in flight after a touch), a miss
// transfers it. Touches (asynchronous access) are counted apart, so the hit ratio is that of the
// kernel's reads in both access modes.
#pragma once

#include <cstdint>

namespace cellrt {

struct CacheStats {
    std::uint64_t hits = 0;             // line lookups of reads that found the line
    std::uint64_t misses = 0;           // line lookups of reads that had to transfer it
    std::uint64_t prefetches = 0;       // touches that started a transfer
    std::uint64_t touch_hits = 0;       // touches that found the line already there
    std::uint64_t bytes = 0;            // bytes transferred into the cache (whole lines)
    std::uint64_t evictions = 0;        // valid lines replaced
    std::uint64_t stale_waits = 0;      // waits whose touched line was evicted before them (no re-touch)

    double hit_ratio() const {
        return hits + misses ? static_cast<double>(hits) / static_cast<double>(hits + misses) : 0.0;
    }

    CacheStats& operator+=(const CacheStats& o) {
        hits += o.hits; misses += o.misses; prefetches += o.prefetches; touch_hits += o.touch_hits;
        bytes += o.bytes; evictions += o.evictions; stale_waits += o.stale_waits;
        return *this;
    }
};

}  // namespace cellrt
