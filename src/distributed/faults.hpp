// The test suite's faults for cellrt-mpi (tests/test_distributed.cpp, docs/DISTRIBUTED.md), named by
// CELLRT_MPI_FAULT=KIND:RANK (passed with `mpirun -x`): kill and stall (tile_farm.cpp), noshm and
// apart (tile_window.cpp).
#pragma once

#include <cstdlib>
#include <string_view>

namespace cellrt::distributed {

// Whether CELLRT_MPI_FAULT names `kind`, for any rank.
inline bool fault_named(std::string_view kind) {
    const char* f = std::getenv("CELLRT_MPI_FAULT");
    return f && std::string_view(f).starts_with(kind) && f[kind.size()] == ':';
}

// Whether CELLRT_MPI_FAULT names `kind` for rank `rank`.
inline bool fault_named(std::string_view kind, int rank) {
    return fault_named(kind) && std::atoi(std::getenv("CELLRT_MPI_FAULT") + kind.size() + 1) == rank;
}

}  // namespace cellrt::distributed
