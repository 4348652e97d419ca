// Main memory as the local-store model sees it: the arrays a traversal reads (nodes, leaf index
// entries, triangles), each placed at a 4 KiB aligned address of its own in a model address space.
// Cache sets, conflicts and so every statistic then depend only on the structure, never on where the
// host's allocator happened to put the arrays. A line never spans two arrays (lines are at most 4 KiB).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cellrt::detail {

class MainMemory {
public:
    static constexpr std::uint64_t kAlign = 4096;

    // Maps `bytes` bytes at `data` (which must outlive this object) and returns their model address.
    std::uint64_t add(const void* data, std::size_t bytes);

    // The DMA's copy: `bytes` bytes of main memory from model address `address` into `out`. Bytes past
    // the end of an array (the tail of its last line) read as zero.
    void copy(std::uint64_t address, std::uint32_t bytes, std::byte* out) const;

private:
    struct Region {
        std::uint64_t base;
        const std::byte* data;
        std::size_t bytes;
    };
    std::vector<Region> regions_;
    std::uint64_t end_ = kAlign;  // address 0 stays unmapped
};

}  // namespace cellrt::detail
