// The kd-tree node: 8 bytes, as in the study and in Wald & Havran's layout. The two children of an
// inner node are adjacent (a pair starting at an even index), so one 16-byte aligned pair, and one
// cache line of the local-store model, holds both siblings.
//
//   inner: [ split position (float) | axis (2 bits) + index of the child pair << 2 ]
//   leaf:  [ triangle count         | 3             + first entry in the index array << 2 ]
#pragma once

#include <bit>
#include <cstdint>

#include "cellrt/host_device.hpp"

namespace cellrt::detail {

class KdNode {
public:
    static constexpr std::uint32_t kLeafTag = 3;
    static constexpr std::uint32_t kMaxIndex = (1u << 30) - 1;

    static KdNode inner(int axis, float split, std::uint32_t children) {
        return KdNode(std::bit_cast<std::uint32_t>(split), static_cast<std::uint32_t>(axis) | (children << 2));
    }
    static KdNode leaf(std::uint32_t first, std::uint32_t count) { return KdNode(count, kLeafTag | (first << 2)); }

    CELLRT_HD bool is_leaf() const { return (word_ & 3u) == kLeafTag; }
    CELLRT_HD int axis() const { return static_cast<int>(word_ & 3u); }
    CELLRT_HD float split() const { return std::bit_cast<float>(payload_); }
    CELLRT_HD std::uint32_t children() const { return word_ >> 2; }  // left child; the right one follows it
    CELLRT_HD std::uint32_t first() const { return word_ >> 2; }
    CELLRT_HD std::uint32_t count() const { return payload_; }
    // The same node with its child pair (inner) or first entry (leaf) moved to `i`.
    KdNode with_index(std::uint32_t i) const { return KdNode(payload_, (word_ & 3u) | (i << 2)); }

    KdNode() = default;
    friend bool operator==(const KdNode&, const KdNode&) = default;

private:
    KdNode(std::uint32_t payload, std::uint32_t word) : payload_(payload), word_(word) {}
    std::uint32_t payload_ = 0;
    std::uint32_t word_ = 0;
};
static_assert(sizeof(KdNode) == 8, "the study's kd-tree node is 8 bytes");

}  // namespace cellrt::detail
