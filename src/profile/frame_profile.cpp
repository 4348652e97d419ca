#include "frame_profile.hpp"

#include "cellrt/error.hpp"
#include "measured_accelerator.hpp"
#include "simd/isa.hpp"

namespace cellrt::profile {
namespace {

RenderOptions single_threaded(const RenderOptions& options) {
    RenderOptions o = options;
    o.threads = 1;
    o.count = false;  // work counters change the kernels' code; they are collected by a render of their own
    return o;
}

}  // namespace

RegionCounts measure_with_counters(const Scene& scene, const Accelerator& accel, const RenderOptions& options) {
    const RenderOptions o = single_threaded(options);
    RegionCounts counts;
    {
        HardwareCounters whole = HardwareCounters::open_or_throw(HardwareCounters::Threads::calling_and_new);
        const MeasuredAccelerator plain(accel, MeasuredAccelerator::Counting::none);
        whole.count([&] { render(scene, plain, o); });
        counts.render = whole.read();
    }
    const MeasuredAccelerator measured(accel, MeasuredAccelerator::Counting::hardware);
    render(scene, measured, o);
    counts.traversal = measured.counts();
    return counts;
}

void render_under_callgrind(const Scene& scene, const Accelerator& accel, const RenderOptions& options) {
    if (!client_requests_available())
        throw Error("this build has no callgrind client requests (valgrind/callgrind.h was missing when it was "
                    "compiled): install valgrind and rebuild");
    const MeasuredAccelerator measured(accel, MeasuredAccelerator::Counting::none);
    const RenderOptions o = single_threaded(options);
    start_instrumentation();
    try {
        render(scene, measured, o);
    } catch (...) {
        stop_instrumentation();
        throw;
    }
    stop_instrumentation();
}

AccelConfig config_for_callgrind(AccelConfig config, std::string& note) {
    if (config.simd == "off") return config;
    const detail::Isa isa = detail::parse_isa(config.simd);
    if (isa != detail::Isa::avx512) {
        config.simd = detail::to_string(isa);
        return config;
    }
    if (config.simd != "auto")
        throw Error("SIMD instruction set avx512: valgrind cannot run AVX-512 code; profile it with hardware "
                    "counters, or choose avx2");
    note = "valgrind cannot run AVX-512 code: profiling the avx2 packets instead";
    config.simd = detail::to_string(detail::Isa::avx2);
    return config;
}

CallgrindOptions callgrind_options(Region region) {
    CallgrindOptions o;
    o.instrument_at_start = false;
    if (region == Region::traversal) o.toggle_collect = MeasuredAccelerator::callgrind_toggles();
    return o;
}

}  // namespace cellrt::profile
