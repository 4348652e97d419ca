#include "software_cache.hpp"

#include <bit>

namespace cellrt::detail {

SoftwareCache::SoftwareCache(const CacheLayout& layout)
    : layout_(layout),
      line_shift_(std::countr_zero(layout.line_bytes)),
      data_(layout.capacity()),
      tags_(layout.lines(), kEmpty),
      last_use_(layout.lines(), 0),
      ready_(layout.lines(), 0) {}

std::uint32_t SoftwareCache::find(std::uint64_t line) const {
    const std::uint32_t first = first_slot(line);
    for (std::uint32_t s = first; s < first + layout_.ways; ++s)
        if (tags_[s] == line) return s;
    return kAbsent;
}

std::uint32_t SoftwareCache::place(std::uint64_t line) {
    const std::uint32_t first = first_slot(line);
    std::uint32_t victim = first;
    for (std::uint32_t s = first; s < first + layout_.ways; ++s) {
        if (tags_[s] == kEmpty) {
            victim = s;
            break;
        }
        if (last_use_[s] < last_use_[victim]) victim = s;
    }
    if (tags_[victim] != kEmpty) ++stats.evictions;
    tags_[victim] = line;
    use(victim);
    return victim;
}

}  // namespace cellrt::detail
