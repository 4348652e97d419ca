// The registry: every structure this binary offers, by kind. The trees come from the one list
// (structures.hpp); brute force, the wide BVH, the router over packets and the BVH (`auto`) and
// Embree are backends of their own.
#include "cellrt/accel.hpp"

#include <algorithm>
#include <functional>

#include "accel/cuda_registry.hpp"
#include "accel/local_store_registry.hpp"
#include "accel/packet_table.hpp"
#include "accel/routed_accelerator.hpp"
#include "accel/structures.hpp"
#include "accel/tree_accelerator.hpp"
#include "accel/brute_force_listing.hpp"
#include "bvh/bvh_accel.hpp"
#include "cellrt/brute_force.hpp"
#include "cellrt/error.hpp"
#include "kernel/named.hpp"
#include "localstore/model_accelerator.hpp"
#ifdef CELLRT_HAVE_EMBREE
#include "embree/embree_accel.hpp"
#endif

namespace cellrt {
namespace {

using Factory = std::function<std::unique_ptr<Accelerator>(std::span<const Triangle>, const AccelConfig&)>;
using LocalStoreFactory = std::unique_ptr<LocalStoreAccelerator> (*)(std::span<const Triangle>, const AccelConfig&,
                                                                     const LocalStoreConfig&);

struct Entry {
    std::string kind;
    Factory make;
    const ParamTable* params;
    std::vector<std::string> traversals;
    LocalStoreFactory local_store = nullptr;  // trees only
    detail::DeviceFactory device = nullptr;   // trees only, where CUDA was found
    // Whether SIMD "off" picks the single-ray kernels of a kind that has SIMD packets too (brute force
    // and the trees), rather than standing for the best set (bvh, auto) or being only checked (embree).
    bool off_is_single_rays = false;
};

std::vector<Entry> make_entries() {
    std::vector<Entry> entries{{"brute", &make_brute_force, &brute_force_params(), brute_force_traversals(), nullptr,
                                nullptr, true}};
    detail::TreeStructures::for_each([&]<class S>(std::type_identity<S>) {
        entries.push_back({S::kName,
                           [](std::span<const Triangle> triangles, const AccelConfig& config) -> std::unique_ptr<Accelerator> {
                               return std::make_unique<detail::TreeAccelerator<S>>(
                                   triangles, config, detail::packet_kernels_for(config));
                           },
                           &S::param_table(), detail::names_of(S::kTraversals), &detail::make_model<S>, nullptr, true});
    });
    entries.push_back({"bvh",
                       [](std::span<const Triangle> triangles, const AccelConfig& config) {
                           return make_bvh(triangles, config, detail::bvh_kernels_for(config));
                       },
                       &bvh_params(), bvh_traversals()});
    entries.push_back({"auto", &detail::make_routed, &detail::routed_params(), detail::routed_traversals()});
#ifdef CELLRT_HAVE_EMBREE
    entries.push_back({"embree", &make_embree, &embree_params(), embree_traversals()});
#endif
#ifdef CELLRT_HAVE_CUDA
    for (const detail::DeviceEntry& d : detail::cuda_factories())
        for (Entry& e : entries)
            if (e.kind == d.kind) e.device = d.make;
#endif
    return entries;
}

const std::vector<Entry>& entries() {
    static const std::vector<Entry> all = make_entries();
    return all;
}

// The kind's entry, or nullptr.
const Entry* find_entry(const std::string& kind) {
    for (const Entry& e : entries())
        if (e.kind == kind) return &e;
    return nullptr;
}

const Entry& entry(const std::string& kind) {
    if (const Entry* e = find_entry(kind)) return *e;
    throw Error("unknown accelerator '" + kind + "' (choose one of: " + detail::join_names(accelerator_kinds()) + ")");
}

}  // namespace

std::vector<std::string> accelerator_kinds() {
    std::vector<std::string> kinds;
    for (const Entry& e : entries()) kinds.push_back(e.kind);
    return kinds;
}

const ParamTable& accelerator_params(const std::string& kind) { return *entry(kind).params; }

const std::vector<std::string>& accelerator_traversals(const std::string& kind) { return entry(kind).traversals; }

// Non-finite vertices are refused here (and in make_local_store_accelerator), once for every kind and
// before any build meets them.
std::unique_ptr<Accelerator> make_accelerator(std::span<const Triangle> triangles, const AccelConfig& config) {
    if (config.device == "cuda") return make_device_accelerator(triangles, config);
    if (config.device != "cpu") throw Error("device '" + config.device + "' is not one of: cpu, cuda");
    const Entry& e = entry(config.kind);
    check_finite(triangles);
    // Found by audit (2026-12-07): the C API and Python built "kd:rec+auto" and reported it as such,
    // while its packets traced every batch.
    if (names_replaced_traversal(config))
        throw Error("'" + format_accel_config(config) + "' names a single-ray kernel ('" + config.traversal +
                    "') and SIMD packets ('" + config.simd + "'), which would replace it: leave one of them out");
    return e.make(triangles, config);
}

bool names_replaced_traversal(const AccelConfig& config) {
    if (config.simd == "off" || config.traversal.empty()) return false;
    const auto& trees = entries();
    const auto e = std::find_if(trees.begin(), trees.end(), [&](const Entry& t) { return t.kind == config.kind; });
    // Brute force's "loop" is such a kernel too ("brute:loop+auto" was built as packets and reported
    // as "packet"; found by audit, 2026-12-07).
    return e != trees.end() && (e->local_store || e->kind == "brute") &&
           std::find(e->traversals.begin(), e->traversals.end(), config.traversal) != e->traversals.end();
}

std::unique_ptr<DeviceAccelerator> make_device_accelerator(std::span<const Triangle> triangles,
                                                           const AccelConfig& config) {
    const Entry& e = entry(config.kind);
#ifndef CELLRT_HAVE_CUDA
    throw Error("device 'cuda': " + cuda_device_info().reason);
#endif
    if (!e.device) {
        std::vector<std::string> trees;
        for (const Entry& t : entries())
            if (t.device) trees.push_back(t.kind);
        throw Error("the CUDA backend runs the trees (" + detail::join_names(trees) + "), not '" + config.kind + "'");
    }
    if (config.simd != "off")
        throw Error("the CUDA backend runs the single-ray kernels, not SIMD packets (simd '" + config.simd + "')");
    check_finite(triangles);
    return e.device(triangles, config);
}

std::unique_ptr<LocalStoreAccelerator> make_local_store_accelerator(std::span<const Triangle> triangles,
                                                                    const AccelConfig& config,
                                                                    const LocalStoreConfig& local_store) {
    const Entry& e = entry(config.kind);
    if (!e.local_store) {
        std::vector<std::string> trees;
        for (const Entry& t : entries())
            if (t.local_store) trees.push_back(t.kind);
        throw Error("the local-store model runs the trees (" + detail::join_names(trees) + "), not '" + config.kind +
                    "'");
    }
    if (config.simd != "off")
        throw Error("the local-store model runs the single-ray kernels, not SIMD packets (simd '" + config.simd +
                    "')");
    check_finite(triangles);
    return e.local_store(triangles, config, local_store);
}

AccelConfig default_accel_config(const std::string& device) {
    AccelConfig c;
    if (device == "cuda") {
        c.kind = "kd";
    } else {
        c.kind = "auto";
        c.params = {{"packets", "bvh"}};
    }
    c.device = device;
    return c;
}

AccelConfig parse_accel_config(std::string spec) {
    AccelConfig c;
    if (const auto at = spec.find('@'); at != std::string::npos) {
        const std::string params = spec.substr(at + 1);
        spec.resize(at);
        for (std::size_t b = 0; b <= params.size();) {
            const std::size_t e = std::min(params.find(',', b), params.size());
            const std::string kv = params.substr(b, e - b);
            const auto eq = kv.find('=');
            if (eq == std::string::npos || eq == 0)
                throw Error("accelerator parameter '" + kv + "' must have the form NAME=VALUE");
            if (!c.params.emplace(kv.substr(0, eq), kv.substr(eq + 1)).second)
                throw Error("accelerator parameter '" + kv.substr(0, eq) + "' is given twice");
            b = e + 1;
        }
    }
    if (const auto plus = spec.find('+'); plus != std::string::npos) {
        c.simd = spec.substr(plus + 1);
        spec.resize(plus);
        if (c.simd.empty()) throw Error("no SIMD instruction set after '+'");
    }
    const auto colon = spec.find(':');
    c.kind = spec.substr(0, colon);
    if (colon != std::string::npos) {
        c.traversal = spec.substr(colon + 1);
        if (c.traversal.empty()) throw Error("no traversal after ':'");
    }
    return c;
}

std::string format_accel_config(const AccelConfig& config) {
    std::string s = config.kind;
    if (!config.traversal.empty()) s += ":" + config.traversal;
    // "off" is written where it is all that names the single-ray kernel of a structure that has SIMD
    // packets too: a bare "kd" is the packets for the CLI and Python (their SIMD default is auto) and
    // the single rays for the C API and the benchmarks, so "kd", copied from one to the other, built
    // another tree (found by audit, 2026-12-07).
    const Entry* e = find_entry(config.kind);
    const bool off_names_the_kernel = config.traversal.empty() && e && e->off_is_single_rays;
    if (config.simd != "off" || off_names_the_kernel) s += "+" + config.simd;
    char separator = '@';
    for (const auto& [name, value] : config.params) {
        s += separator + name + "=" + value;
        separator = ',';
    }
    return s;
}

}  // namespace cellrt
