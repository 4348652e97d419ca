// The checks every accelerator call passes before a structure sees it. Out of line on purpose: one
// call per batch, and the profiles (bench/ab_callgrind.py, bench/step_costs.py) find the entry of
// every batch under the name Accelerator::intersect / occluded.
#include "cellrt/accelerator.hpp"

#include "cellrt/error.hpp"

namespace cellrt {
namespace {

void check_lengths(const char* call, std::size_t rays, std::size_t results, const char* what) {
    if (rays != results)
        throw Error(std::string(call) + ": " + std::to_string(rays) + " rays but " + std::to_string(results) + " " +
                    what + " (the spans must have the same length)");
}

}  // namespace

void Accelerator::intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const {
    check_lengths("intersect", rays.size(), hits.size(), "hits");
    do_intersect(rays, hits, counters);
}

void Accelerator::occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                           TraversalCounters* counters) const {
    check_lengths("occluded", rays.size(), occluded.size(), "results");
    do_occluded(rays, occluded, counters);
}

}  // namespace cellrt
