// The geometry of one software cache of the local-store model (the study's section 4.3): line size,
// number of sets and ways. Capacity = line x sets x ways. The study used direct-mapped and 4-way
// set-associative caches with lines of 16 B .. 4 KiB and at most 16 KiB of data per cache.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace cellrt {

struct CacheLayout {
    static constexpr std::uint32_t kMinLine = 16;    // the smallest DMA transfer worth a line
    static constexpr std::uint32_t kMaxLine = 4096;  // the largest line the study tried
    static constexpr std::uint32_t kMaxSets = 1u << 20;

    std::uint32_t line_bytes = 128;
    std::uint32_t sets = 128;
    std::uint32_t ways = 1;  // 1: direct-mapped; 4: 4-way set-associative with LRU replacement

    std::size_t lines() const { return static_cast<std::size_t>(sets) * ways; }
    std::size_t capacity() const { return lines() * line_bytes; }
    // "LINExSETS" for a direct-mapped cache, "LINExSETSxWAYS" otherwise (what parse_cache_layout reads).
    std::string to_string() const;
    friend bool operator==(const CacheLayout&, const CacheLayout&) = default;
};

// Throws cellrt::Error naming `what` unless the line is a power of two in [16, 4096], the sets a
// power of two in [1, 2^20] and the ways 1 or 4.
void validate_cache_layout(const CacheLayout& layout, const std::string& what);

// Reads LINExSETS[xWAYS] (e.g. "128x128", "64x64x4") and validates it; errors name `option`.
CacheLayout parse_cache_layout(const std::string& option, const std::string& text);

}  // namespace cellrt
