// The trees this binary offers: the one list. Adding a structure is one folder with its descriptor
// (see kdtree/kd_structure.hpp) and one entry in TreeStructures; the registry (accel.cpp), the SIMD
// packets (kernels_<isa>.cpp) and the local-store model (local_store_registry.cpp) are instantiated
// for every entry.
#pragma once

#include <type_traits>

#include "bih/bih_structure.hpp"
#include "kdtree/kd_structure.hpp"
#include "packet/packet.hpp"

namespace cellrt::detail {

template <class... S>
struct StructureList {
    // The packet kernels of one instruction set for every structure of the list.
    using PacketKernels = PacketTable<typename S::Traits...>;

    // Calls fn(std::type_identity<S>{}) for every structure, in list order.
    template <class Fn>
    static void for_each(Fn&& fn) {
        (fn(std::type_identity<S>{}), ...);
    }
};

using TreeStructures = StructureList<KdStructure, BihStructure>;
using PacketKernels = TreeStructures::PacketKernels;

}  // namespace cellrt::detail
