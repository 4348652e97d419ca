// The cost model of a worker core (the study's SPE), in processor cycles: the one place where the
// local-store model's timing parameters live (docs/LOCALSTORE.md gives their sources).
//
// A worker's clock advances by the work it does (ray set-up, traversal steps, leaves, triangle tests,
// local-store loads, software-cache lookups and miss handling) and, when it needs data that is not in
// its local store yet, by the wait for the transfer: latency plus bytes / bandwidth, behind the
// transfers issued before it. Asynchronous transfers overlap with the work done between the touch
// that starts them and the wait that needs them.
#pragma once

#include <cstdint>

namespace cellrt {

struct CostModel {
    // The processor: a 3.2 GHz Cell SPE.
    double clock_ghz = 3.2;
    // Main memory: a DMA transfer's data arrives `dma_latency` cycles after it is issued (the study's
    // ~900 cycles), plus its bytes at `bytes_per_cycle` (25.6 GB/s at 3.2 GHz). Transfers share the
    // bus in issue order; at most `dma_queue` are in flight (the MFC's 16-entry queue).
    std::uint32_t dma_latency = 900;
    double bytes_per_cycle = 8.0;
    std::uint32_t dma_queue = 16;
    // The local store: one load (SPU load latency) for each node, index entry or triangle read.
    std::uint32_t ls_access = 6;
    // Software cache: address split and tag compare per line looked up; a miss's handling (victim
    // choice, directory update, DMA command) on top of the transfer.
    std::uint32_t cache_lookup = 10;
    std::uint32_t miss_handling = 40;
    // Work: preparing a ray, one inner-node step, entering a leaf, one watertight triangle test.
    std::uint32_t ray_setup = 60;
    std::uint32_t inner_node = 16;
    std::uint32_t leaf = 8;
    std::uint32_t triangle_test = 40;
    // Branches: the SPU has no branch predictor; a data-dependent branch the static hint gets wrong
    // costs `branch_miss` cycles. The branched traversals take one such branch per inner node, wrong
    // `branched_miss_rate` of the time; the branchless ones (section 4.5) replace it by
    // `branchless_extra` cycles of select and store instructions.
    std::uint32_t branch_miss = 18;
    double branched_miss_rate = 0.5;
    std::uint32_t branchless_extra = 4;

    // Cycles of one inner-node step of a branched or a branchless traversal.
    std::uint32_t inner_step(bool branchless) const {
        return inner_node + (branchless ? branchless_extra
                                        : static_cast<std::uint32_t>(branch_miss * branched_miss_rate + 0.5));
    }
    double seconds(std::uint64_t cycles) const { return static_cast<double>(cycles) / (clock_ghz * 1e9); }
};

}  // namespace cellrt
