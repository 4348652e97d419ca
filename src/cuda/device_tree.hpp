// A tree as the CUDA backend holds it: its three arrays (nodes, leaf entries, triangles; the layout
// the tree's descriptor gives its TreeView) packed into one allocation, each at a 16-byte aligned
// offset, so that one copy moves the tree and a pair of sibling nodes never straddles a 16-byte line
// (kd_node.hpp). Host code packs it; both sides rebuild the TreeView from the packed bytes, and the
// CPU tests trace that rebuilt view (tests/test_device_code.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "cellrt/host_device.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {

struct PackedTree {
    std::size_t nodes = 0, entries = 0, triangles = 0;  // element counts
    std::size_t entries_offset = 0, triangles_offset = 0, bytes = 0;
    Box3 bounds;
};

inline constexpr std::size_t kPackedAlignment = 16;

CELLRT_HD inline std::size_t align_up(std::size_t n, std::size_t to) { return (n + to - 1) / to * to; }

template <class Traits>
PackedTree packed_layout(std::size_t nodes, std::size_t entries, std::size_t triangles, const Box3& bounds) {
    PackedTree p{nodes, entries, triangles, 0, 0, 0, bounds};
    p.entries_offset = align_up(nodes * sizeof(typename Traits::Node), kPackedAlignment);
    p.triangles_offset = align_up(p.entries_offset + entries * sizeof(std::uint32_t), kPackedAlignment);
    p.bytes = align_up(p.triangles_offset + triangles * sizeof(Triangle), kPackedAlignment);
    return p;
}

// Writes the arrays into `out` (layout.bytes bytes, aligned to kPackedAlignment); padding is zeroed.
template <class Traits>
void pack_tree(std::span<const typename Traits::Node> nodes, std::span<const std::uint32_t> entries,
               std::span<const Triangle> triangles, const PackedTree& layout, std::byte* out) {
    std::memset(out, 0, layout.bytes);
    if (!nodes.empty()) std::memcpy(out, nodes.data(), nodes.size_bytes());
    if (!entries.empty()) std::memcpy(out + layout.entries_offset, entries.data(), entries.size_bytes());
    if (!triangles.empty()) std::memcpy(out + layout.triangles_offset, triangles.data(), triangles.size_bytes());
}

// The TreeView of a packed tree at `base` (host or device memory).
template <class Traits>
CELLRT_HD TreeView<Traits> packed_view(const std::byte* base, const PackedTree& layout) {
    return {reinterpret_cast<const typename Traits::Node*>(base),
            reinterpret_cast<const std::uint32_t*>(base + layout.entries_offset),
            reinterpret_cast<const Triangle*>(base + layout.triangles_offset), layout.bounds};
}

}  // namespace cellrt::detail
