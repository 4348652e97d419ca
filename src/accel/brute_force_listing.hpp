// Brute force's parameters (none) and traversals ("loop"), for the registry's listings.
#pragma once

#include <string>
#include <vector>

#include "cellrt/params.hpp"

namespace cellrt {

const ParamTable& brute_force_params();
const std::vector<std::string>& brute_force_traversals();

}  // namespace cellrt
