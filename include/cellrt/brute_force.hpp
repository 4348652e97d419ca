// Brute force: every ray tests every triangle. The reference that all tests compare against.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt {

std::unique_ptr<Accelerator> make_brute_force(std::span<const Triangle> triangles, const AccelConfig& config);

// Its parameters (none) and traversals ("loop"), for the registry's listings.
const ParamTable& brute_force_params();
const std::vector<std::string>& brute_force_traversals();

}  // namespace cellrt
