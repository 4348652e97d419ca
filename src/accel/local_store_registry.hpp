// The local-store model of every tree the registry lists (structures.hpp).
#pragma once

#include <memory>
#include <span>

#include "cellrt/accelerator.hpp"
#include "localstore/local_store.hpp"

namespace cellrt {

// Builds `config.kind` (a listed tree, with its build parameters; single-ray kernels) over `triangles`
// (which must outlive it, unchanged: the kd-tree's model reads them on every call) to be traced through the
// model `local_store`. Throws cellrt::Error for another kind, SIMD packets, a bad parameter, an unknown
// traversal, a configuration the budget refuses or a triangle with a NaN or infinite coordinate.
std::unique_ptr<LocalStoreAccelerator> make_local_store_accelerator(std::span<const Triangle> triangles,
                                                                    const AccelConfig& config,
                                                                    const LocalStoreConfig& local_store);

}  // namespace cellrt
