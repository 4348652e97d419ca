// The kd-tree behind the accelerator boundary (`--accel kd`).
#pragma once

#include <string>
#include <vector>

#include "cellrt/accel.hpp"
#include "kd_traversal.hpp"

namespace cellrt::detail {

// `-P` build parameters of `config`, validated (docs/KDTREE.md); throws cellrt::Error naming a bad one.
KdBuildParams read_kd_params(const AccelConfig& config);
// The single-ray traversals by name, the default first, and the one a name selects.
const std::vector<std::string>& kd_traversal_names();
KdTraversal kd_traversal(const std::string& name);

std::unique_ptr<Accelerator> make_kdtree(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt::detail
