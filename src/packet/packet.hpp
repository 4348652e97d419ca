// SIMD packets (packet_kernels.inl; kLanes rays in SIMD lanes, not the renderer's packets of pixels):
// the entry points of one instruction set's kernels, for brute force and for every tree, reached
// through a table chosen once per accelerator, never per ray. The
// kernels are templates over a tree's traits (kernel/stack_traversal.hpp) and read a tree through its
// TreeView; the registry (src/accel) compiles them once per instruction set for the structures it lists.
#pragma once

#include <cstdint>
#include <span>
#include <tuple>

#include "cellrt/accelerator.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {

template <class Traits>
struct TreePacketKernels {
    void (*closest)(const TreeView<Traits>&, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*any)(const TreeView<Traits>&, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
};

struct BrutePacketKernels {
    void (*closest)(std::span<const Triangle>, std::span<const Ray>, std::span<Hit>, TraversalCounters*);
    void (*any)(std::span<const Triangle>, std::span<const Ray>, std::span<std::uint8_t>, TraversalCounters*);
};

// One instruction set's kernels for brute force and for the trees of traits `Traits...`.
template <class... Traits>
struct PacketTable {
    int lanes;
    BrutePacketKernels brute;
    std::tuple<TreePacketKernels<Traits>...> trees;

    template <class T>
    const TreePacketKernels<T>& tree() const {
        return std::get<TreePacketKernels<T>>(trees);
    }
};

}  // namespace cellrt::detail
