#include "measured_accelerator.hpp"

#include "cellrt/error.hpp"

namespace cellrt::profile {

template <class Call>
void MeasuredAccelerator::measure(Call&& call) const {
    if (counting_ == Counting::none) return call();
    if (!counters_) {
        counters_ = HardwareCounters::open_or_throw(HardwareCounters::Threads::calling);
        owner_ = std::this_thread::get_id();
    } else if (owner_ != std::this_thread::get_id()) {
        throw Error("a measured accelerator with hardware counting was called from a second thread; profile with "
                    "one render thread");
    }
    counters_->count(call);
}

void MeasuredAccelerator::do_intersect(std::span<const Ray> rays, std::span<Hit> hits,
                                    TraversalCounters* counters) const {
    measure([&] { inner_.intersect(rays, hits, counters); });
}

void MeasuredAccelerator::do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                                      TraversalCounters* counters) const {
    measure([&] { inner_.occluded(rays, occluded, counters); });
}

EventCounts MeasuredAccelerator::counts() const { return counters_ ? counters_->read() : EventCounts{}; }

std::vector<std::string> MeasuredAccelerator::callgrind_toggles() {
    return {"cellrt::profile::MeasuredAccelerator::do_intersect(*",
            "cellrt::profile::MeasuredAccelerator::do_occluded(*"};
}

}  // namespace cellrt::profile
