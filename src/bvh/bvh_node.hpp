// The wide BVH's node and leaf (after Embree's BVH8 with Triangle8 leaves; Wald, Benthin, Boulos,
// "Getting Rid of Packets", 2008): a node holds its eight children's boxes as structure of arrays, so
// that one ray meets all eight in a few SIMD instructions; a leaf holds up to eight triangles the same
// way, tested against the ray in one pass of the watertight test, lane by lane.
//
//   child word: inner child  its node index (< 2^31)
//               leaf         kLeafBit | leaf index << 3 | (triangles - 1)
//               empty slot   kEmptyChild (its box is empty: lo = +inf, hi = -inf, which no ray meets)
#pragma once

#include <cstdint>

namespace cellrt::detail {

inline constexpr int kBvhWidth = 8;

struct alignas(64) BvhNode {
    static constexpr std::uint32_t kLeafBit = 1u << 31;
    static constexpr std::uint32_t kEmptyChild = ~0u;

    float lo[3][kBvhWidth];  // lo[axis][child]
    float hi[3][kBvhWidth];
    std::uint32_t child[kBvhWidth];

    static bool is_leaf(std::uint32_t word) { return (word & kLeafBit) != 0; }
    static std::uint32_t leaf_index(std::uint32_t word) { return (word & ~kLeafBit) >> 3; }
    static std::uint32_t leaf_count(std::uint32_t word) { return (word & 7u) + 1; }
    static std::uint32_t leaf_word(std::uint32_t index, std::uint32_t count) {
        return kLeafBit | index << 3 | (count - 1);
    }
};
static_assert(sizeof(BvhNode) == 256, "a wide BVH node is four 64-byte lines: 8 boxes and 8 child words");

// Up to eight triangles: v[vertex][axis][lane], and each lane's index in the scene (kNoHit: unused).
struct alignas(64) BvhLeaf {
    float v[3][3][kBvhWidth];
    std::uint32_t prim[kBvhWidth];
};
static_assert(sizeof(BvhLeaf) == 320, "a wide BVH leaf is nine lanes of coordinates and one of indices: five cache lines");

}  // namespace cellrt::detail
