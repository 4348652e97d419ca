// What one measured region cost in instructions and branches: read from the processor's counters, or
// simulated by callgrind (which has no cycles). The study's Tables 5-3, 5-4 and 5-7 give these figures
// for the whole program and for the traversal loop alone.
#pragma once

#include <cstdint>
#include <optional>

namespace cellrt::profile {

struct EventCounts {
    std::uint64_t instructions = 0;
    // Hardware: every retired branch instruction. callgrind: conditional and indirect branches only
    // (direct jumps, calls and returns are not simulated).
    std::uint64_t branches = 0;
    std::uint64_t mispredictions = 0;
    std::optional<std::uint64_t> cycles;  // absent under simulation: there is no honest value

    std::optional<double> ipc() const {
        if (!cycles || *cycles == 0) return std::nullopt;
        return static_cast<double>(instructions) / static_cast<double>(*cycles);
    }
    std::optional<double> cpi() const {
        if (!cycles || instructions == 0) return std::nullopt;
        return static_cast<double>(*cycles) / static_cast<double>(instructions);
    }
};

}  // namespace cellrt::profile
