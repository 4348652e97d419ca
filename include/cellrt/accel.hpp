// The registry of acceleration structures: every structure this binary offers, built by kind from
// triangles and a configuration (cellrt/accelerator.hpp), with its parameters and traversals listed.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt {

// Builds the structure `config.kind` over `triangles` (which must outlive the accelerator).
// Throws cellrt::Error for an unknown kind, traversal or parameter, or a parameter out of range.
std::unique_ptr<Accelerator> make_accelerator(std::span<const Triangle> triangles, const AccelConfig& config);

// An accelerator configuration written as one string, as the benchmarks and tests name them:
// KIND[:TRAVERSAL][+SIMD][@NAME=VALUE,...], e.g. "kd:rec", "bih+avx2", "kd+auto@leaf_size=2,bins=64".
// Throws cellrt::Error for a malformed parameter; the parts themselves are checked by make_accelerator.
AccelConfig parse_accel_config(std::string spec);

// Kinds built into this binary ("brute", "kd", "bih", and "embree" where Embree 3 was found).
std::vector<std::string> accelerator_kinds();

// The build parameters of `kind` (empty for none) and its single-ray traversals, the default first.
// Throw cellrt::Error for an unknown kind.
const ParamTable& accelerator_params(const std::string& kind);
const std::vector<std::string>& accelerator_traversals(const std::string& kind);

}  // namespace cellrt
