// An accelerator that measures another: each intersect/occluded call, one batch of rays, is one
// measured region, so that "the traversal alone" excludes everything the renderer does around it (ray
// generation, shading, scheduling), as the study's inner-loop figures do.
//
// With hardware counting, the counters of the calling thread are enabled for the duration of each call
// and summed; they are opened on the first call, so on the render worker's own thread, and every call
// must come from that thread. Without, the calls are where callgrind switches its collection on and
// off (callgrind_toggles()).
#pragma once

#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cellrt/accel.hpp"
#include "event_counts.hpp"
#include "hardware_counters.hpp"

namespace cellrt::profile {

class MeasuredAccelerator final : public Accelerator {
public:
    enum class Counting { none, hardware };

    MeasuredAccelerator(const Accelerator& inner, Counting counting) : inner_(inner), counting_(counting) {}

    AccelStats stats() const override { return inner_.stats(); }
    bool refuses_rays() const override { return inner_.refuses_rays(); }
    void check_rays(std::span<const Ray> rays, std::size_t first) const override { inner_.check_rays(rays, first); }

    // The sums over all calls so far (hardware counting; zero before the first call).
    EventCounts counts() const;

    // callgrind --toggle-collect patterns that collect inside intersect/occluded alone.
    static std::vector<std::string> callgrind_toggles();

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override;
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override;

    template <class Call>
    void measure(Call&& call) const;

    const Accelerator& inner_;
    Counting counting_;
    mutable std::optional<HardwareCounters> counters_;
    mutable std::thread::id owner_;
};

}  // namespace cellrt::profile
