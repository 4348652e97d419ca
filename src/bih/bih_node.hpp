// The BIH node: 12 bytes (Wächter & Keller 2006, section 2.1). An inner node holds two clip planes on
// one axis: the largest coordinate of the left child's triangles and the smallest of the right
// child's; the children are adjacent (a pair). A leaf holds a range of the reordered triangle array.
//
//   inner: [ axis (2 bits) + index of the child pair << 2 | left clip (float) | right clip (float) ]
//   leaf:  [ 3             + first triangle << 2          | triangle count    | unused             ]
#pragma once

#include <bit>
#include <cstdint>

#include "cellrt/host_device.hpp"

namespace cellrt::detail {

class BihNode {
public:
    static constexpr std::uint32_t kLeafTag = 3;
    static constexpr std::uint32_t kMaxIndex = (1u << 30) - 1;

    static BihNode inner(int axis, float left_clip, float right_clip, std::uint32_t children) {
        return BihNode(static_cast<std::uint32_t>(axis) | (children << 2), left_clip, right_clip);
    }
    static BihNode leaf(std::uint32_t first, std::uint32_t count) {
        return BihNode(kLeafTag | (first << 2), std::bit_cast<float>(count), 0.f);
    }

    CELLRT_HD bool is_leaf() const { return (word_ & 3u) == kLeafTag; }
    CELLRT_HD int axis() const { return static_cast<int>(word_ & 3u); }
    // clip(0): the left child's upper bound, clip(1): the right child's lower bound on axis().
    CELLRT_HD float clip(std::uint32_t side) const { return clip_[side]; }
    CELLRT_HD std::uint32_t children() const { return word_ >> 2; }
    CELLRT_HD std::uint32_t first() const { return word_ >> 2; }
    CELLRT_HD std::uint32_t count() const { return std::bit_cast<std::uint32_t>(clip_[0]); }
    BihNode with_index(std::uint32_t i) const { return BihNode((word_ & 3u) | (i << 2), clip_[0], clip_[1]); }

    BihNode() = default;
    bool operator==(const BihNode& o) const {
        return word_ == o.word_ && std::bit_cast<std::uint32_t>(clip_[0]) == std::bit_cast<std::uint32_t>(o.clip_[0]) &&
               std::bit_cast<std::uint32_t>(clip_[1]) == std::bit_cast<std::uint32_t>(o.clip_[1]);
    }

private:
    BihNode(std::uint32_t word, float a, float b) : word_(word), clip_{a, b} {}
    std::uint32_t word_ = 0;
    float clip_[2] = {0.f, 0.f};
};
static_assert(sizeof(BihNode) == 12, "the study's BIH node is 12 bytes");

}  // namespace cellrt::detail
