// The BIH behind the accelerator boundary (`--accel bih`).
#pragma once

#include <string>
#include <vector>

#include "bih_traversal.hpp"
#include "cellrt/accel.hpp"

namespace cellrt::detail {

// `-P` build parameters of `config`, validated (docs/BIH.md); throws cellrt::Error naming a bad one.
BihBuildParams read_bih_params(const AccelConfig& config);
// The single-ray traversals by name, the default first, and the one a name selects.
const std::vector<std::string>& bih_traversal_names();
BihTraversal bih_traversal(const std::string& name);

std::unique_ptr<Accelerator> make_bih(std::span<const Triangle> triangles, const AccelConfig& config);

}  // namespace cellrt::detail
