#include "cache_layout.hpp"

#include <bit>
#include <charconv>

#include "cellrt/error.hpp"

namespace cellrt {

std::string CacheLayout::to_string() const {
    std::string s = std::to_string(line_bytes);
    s += 'x';
    s += std::to_string(sets);
    if (ways != 1) {
        s += 'x';
        s += std::to_string(ways);
    }
    return s;
}

void validate_cache_layout(const CacheLayout& layout, const std::string& what) {
    if (!std::has_single_bit(layout.line_bytes) || layout.line_bytes < CacheLayout::kMinLine ||
        layout.line_bytes > CacheLayout::kMaxLine)
        throw Error(what + ": line size " + std::to_string(layout.line_bytes) +
                    " B must be a power of two from 16 to 4096");
    if (!std::has_single_bit(layout.sets) || layout.sets > CacheLayout::kMaxSets)
        throw Error(what + ": " + std::to_string(layout.sets) + " sets: the number of sets must be a power of two "
                                                                "from 1 to 1048576");
    if (layout.ways != 1 && layout.ways != 4)
        throw Error(what + ": " + std::to_string(layout.ways) + " ways: a cache is direct-mapped (1) or 4-way (4)");
}

CacheLayout parse_cache_layout(const std::string& option, const std::string& text) {
    const Error bad(option + " '" + text + "' must be LINExSETS or LINExSETSxWAYS (e.g. 128x128 or 64x64x4)");
    std::uint32_t fields[3] = {0, 0, 1};
    int count = 0;
    const char* p = text.data();
    const char* const end = p + text.size();
    for (;;) {
        const auto [next, ec] = std::from_chars(p, end, fields[count]);
        if (ec != std::errc() || next == p) throw bad;
        ++count;
        p = next;
        if (p == end) break;
        if (*p != 'x' || count == 3) throw bad;
        ++p;
    }
    if (count < 2) throw bad;
    const CacheLayout layout{fields[0], fields[1], fields[2]};
    validate_cache_layout(layout, option + " '" + text + "'");
    return layout;
}

}  // namespace cellrt
