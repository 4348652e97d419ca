#include "main_memory.hpp"

#include <algorithm>
#include <cstring>

namespace cellrt::detail {

std::uint64_t MainMemory::add(const void* data, std::size_t bytes) {
    const std::uint64_t base = end_;
    regions_.push_back({base, static_cast<const std::byte*>(data), bytes});
    end_ = base + std::max<std::uint64_t>(kAlign, (bytes + kAlign - 1) / kAlign * kAlign);
    return base;
}

void MainMemory::copy(std::uint64_t address, std::uint32_t bytes, std::byte* out) const {
    std::memset(out, 0, bytes);
    for (const Region& r : regions_) {
        if (address + bytes <= r.base || address >= r.base + r.bytes) continue;
        const std::uint64_t from = std::max(address, r.base), to = std::min(address + bytes, r.base + r.bytes);
        std::memcpy(out + (from - address), r.data + (from - r.base), static_cast<std::size_t>(to - from));
    }
}

}  // namespace cellrt::detail
