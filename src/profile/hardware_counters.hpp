// The processor's performance counters through Linux's perf_event_open: instructions, cycles,
// branches and branch mispredictions of user-space code, as one group (scheduled together, enabled
// and disabled together), counting only while enabled. Many virtual machines expose no counters;
// open() then says why in one line and the caller falls back to simulation (callgrind.hpp).
#pragma once

#include <array>
#include <optional>
#include <string>

#include "event_counts.hpp"

namespace cellrt::profile {

class HardwareCounters {
public:
    enum class Threads {
        calling,          // the thread that opens the counters
        calling_and_new,  // that thread and every thread it starts later (summed in when they exit)
    };

    // The counters, disabled, or nullopt with `why` set to one line naming the event and the reason.
    static std::optional<HardwareCounters> open(Threads threads, std::string& why);
    // The same, throwing cellrt::Error with that line when they are unavailable.
    static HardwareCounters open_or_throw(Threads threads);

    HardwareCounters(HardwareCounters&& o) noexcept;
    HardwareCounters& operator=(HardwareCounters&& o) noexcept;
    HardwareCounters(const HardwareCounters&) = delete;
    HardwareCounters& operator=(const HardwareCounters&) = delete;
    ~HardwareCounters();

    void enable();
    void disable();
    // Runs f() with the counters enabled.
    template <class F>
    void count(F&& f) {
        enable();
        try {
            f();
        } catch (...) {
            disable();
            throw;
        }
        disable();
    }
    // Sums over every enabled period so far. Throws cellrt::Error when the group was multiplexed with
    // other users of the counters: its counts would be extrapolations, not counts.
    EventCounts read() const;

private:
    enum Event { instructions, cycles, branches, mispredictions, kEvents };
    HardwareCounters() { fds_.fill(-1); }
    void close_all();
    std::array<int, kEvents> fds_;  // fds_[0] leads the group
};

}  // namespace cellrt::profile
