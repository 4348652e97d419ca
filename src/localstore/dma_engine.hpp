// A worker's DMA engine (the SPE's memory flow controller) in the cost model: transfers queue behind
// one another on the bus, each delivering its data `dma_latency` cycles plus its bytes / bandwidth
// after it starts, and at most `dma_queue` may be in flight; issuing one more waits for the oldest.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "cost_model.hpp"

namespace cellrt::detail {

class DmaEngine {
public:
    explicit DmaEngine(const CostModel& cost)
        : latency_(cost.dma_latency),
          bytes_per_cycle_(cost.bytes_per_cycle),
          in_flight_(std::max(1u, cost.dma_queue), 0) {}

    // Issues a transfer of `bytes` at cycle `now` and returns the cycle its data is in the local store.
    // With the queue full, `now` first moves on to the completion of the oldest transfer.
    std::uint64_t issue(std::uint64_t& now, std::uint32_t bytes) {
        now = std::max(now, in_flight_[oldest_]);
        const std::uint64_t start = std::max(now, bus_free_);
        bus_free_ = start + static_cast<std::uint64_t>(std::ceil(bytes / bytes_per_cycle_));
        const std::uint64_t ready = bus_free_ + latency_;
        in_flight_[oldest_] = ready;  // completions come in issue order, so the ring's next entry is the oldest
        oldest_ = (oldest_ + 1) % in_flight_.size();
        return ready;
    }

private:
    std::uint64_t latency_;
    double bytes_per_cycle_;
    std::vector<std::uint64_t> in_flight_;  // completion cycles of the last dma_queue transfers
    std::size_t oldest_ = 0;
    std::uint64_t bus_free_ = 0;
};

}  // namespace cellrt::detail
