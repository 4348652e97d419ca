// One software cache of a worker's local store (the study's section 4.3, after the Cell SDK's
// software-managed cache): lines of the main-memory address space kept in a line buffer, found by
// set (address / line mod sets) and tag, placed direct-mapped or in the least recently used of 4 ways.
// The cache only places lines and keeps their bytes; the worker's local store (worker_store.hpp)
// copies the bytes in, keeps time and counts hits and misses.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cache_layout.hpp"
#include "cache_stats.hpp"

namespace cellrt::detail {

class SoftwareCache {
public:
    static constexpr std::uint32_t kAbsent = ~0u;

    explicit SoftwareCache(const CacheLayout& layout);

    const CacheLayout& layout() const { return layout_; }
    std::uint32_t line_bytes() const { return layout_.line_bytes; }
    std::uint64_t line_of(std::uint64_t address) const { return address & ~std::uint64_t(layout_.line_bytes - 1); }

    // The slot (set * ways + way) holding the line that starts at `line`, or kAbsent. Changes nothing.
    std::uint32_t find(std::uint64_t line) const;
    // Gives the line starting at `line` a slot in its set: an empty way, else the least recently used
    // one (the only one when direct-mapped), whose line is evicted. The caller fills the bytes.
    std::uint32_t place(std::uint64_t line);
    // Marks a slot the most recently used of its set.
    void use(std::uint32_t slot) { last_use_[slot] = ++uses_; }

    std::byte* bytes(std::uint32_t slot) { return data_.data() + static_cast<std::size_t>(slot) * layout_.line_bytes; }
    std::uint64_t line_at(std::uint32_t slot) const { return tags_[slot]; }
    // The cycle at which the slot's transfer completes (in the past once the line has arrived).
    std::uint64_t& ready(std::uint32_t slot) { return ready_[slot]; }

    CacheStats stats;

private:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
    std::uint32_t first_slot(std::uint64_t line) const {
        return static_cast<std::uint32_t>((line >> line_shift_) & (layout_.sets - 1)) * layout_.ways;
    }

    CacheLayout layout_;
    int line_shift_;
    std::vector<std::byte> data_;
    std::vector<std::uint64_t> tags_;      // line address held by each slot, kEmpty when none
    std::vector<std::uint64_t> last_use_;  // LRU stamps
    std::vector<std::uint64_t> ready_;
    std::uint64_t uses_ = 0;
};

}  // namespace cellrt::detail
