// The registry of acceleration structures: every structure this binary offers, built by kind from
// triangles and a configuration (cellrt/accelerator.hpp), with its parameters and traversals listed.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/device.hpp"
#include "cellrt/params.hpp"

namespace cellrt {

// Builds the structure `config.kind` over `triangles`. Throws cellrt::Error for an unknown kind,
// traversal or parameter, a parameter out of range, a triangle with a NaN or infinite coordinate
// (naming the first), and a tree's single-ray kernel named with SIMD packets, which replace it
// (names_replaced_traversal). An empty span is a scene every ray misses.
//
// What the accelerator keeps: brute force and the kd-tree read `triangles` itself (the kd-tree's
// leaves index it) on every call, so it must outlive the accelerator, unchanged; the BIH keeps a
// reordered copy, the wide BVH copies the triangles into its leaves and Embree into its own buffers,
// so those need `triangles` only during the call. Code that may build any kind keeps the triangles
// alive and unchanged as long as the accelerator. Hits name triangles by their index in `triangles`.
// config.device "cuda" builds the device accelerator below; any other device than "cpu" is refused.
std::unique_ptr<Accelerator> make_accelerator(std::span<const Triangle> triangles, const AccelConfig& config);

// The tree `config.kind` built on the host and traced on the CUDA device (cellrt/device.hpp; config.device
// is not read). Throws cellrt::Error, besides make_accelerator's reasons, for a kind that is not a tree,
// SIMD packets (simd other than "off"), a build without CUDA, or no device (naming CUDA's reason).
// It keeps nothing of `triangles`: the tree and its triangles are copied to the device.
std::unique_ptr<DeviceAccelerator> make_device_accelerator(std::span<const Triangle> triangles, const AccelConfig& config);

// Whether `config` names one of a tree's single-ray kernels (the kd-tree's or the BIH's traversals,
// brute force's "loop") together with SIMD packets (simd other than "off"), which trace the batches in its stead: the
// kernel would be dropped without a word, so make_accelerator refuses it ("kd:rec+auto"). The wide
// BVH's traversals take an instruction set and are not such kernels.
bool names_replaced_traversal(const AccelConfig& config);

// An accelerator configuration written as one string, as the benchmarks and tests name them:
// KIND[:TRAVERSAL][+SIMD][@NAME=VALUE,...], e.g. "kd:rec", "bih+avx2", "kd+auto@leaf_size=2,bins=64".
// Throws cellrt::Error for a malformed or repeated parameter and for an empty traversal or SIMD set after
// ':' or '+'; the parts themselves are checked by make_accelerator.
AccelConfig parse_accel_config(std::string spec);

// The configuration written as parse_accel_config reads it, in one canonical form: the traversal when
// named, the SIMD set unless "off" (written for kd, bih and brute without a traversal, "kd+off": there
// it is what names their single-ray kernel, where the CLI's and Python's default is their packets),
// the parameters sorted by name (e.g. "auto@packets=bvh"). The
// threads and the device are not part of the string. parse_accel_config of the result gives back
// `config`'s kind, traversal, SIMD set and parameters, where no parameter's value holds a ',' (no
// structure accepts one).
std::string format_accel_config(const AccelConfig& config);

// What a caller who names no configuration gets (the C API's NULL, Python's kind=None). On the CPU,
// "auto@packets=bvh": one wide BVH (a build about twice Embree's), each batch routed to the traversal
// that traces its kind fastest (docs/BVH.md). On the GPU ("cuda"), which traces the kd-tree and the
// BIH only, "kd" (docs/GPU.md: the faster of the two there).
AccelConfig default_accel_config(const std::string& device = "cpu");

// Kinds built into this binary ("brute", "kd", "bih", "bvh", "auto", and "embree" where Embree 3 was
// found). Thread safety: every function of this header may be called from any number of threads at
// once; builds run at once are independent.
std::vector<std::string> accelerator_kinds();

// The build parameters of `kind` (empty for none) and its single-ray traversals, the default first.
// Throw cellrt::Error for an unknown kind.
const ParamTable& accelerator_params(const std::string& kind);
const std::vector<std::string>& accelerator_traversals(const std::string& kind);

}  // namespace cellrt
