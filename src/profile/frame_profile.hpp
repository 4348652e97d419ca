// The two regions a profile measures while rendering one frame (the study's Tables 5-3, 5-4 and 5-7):
// the whole render, and the traversal alone, i.e. the accelerator's intersect/occluded calls. The
// frame is rendered single-threaded (options.threads is ignored) and always through a
// MeasuredAccelerator, so that both routes and both regions run the very same code.
#pragma once

#include "callgrind.hpp"
#include "cellrt/render.hpp"
#include "event_counts.hpp"

namespace cellrt::profile {

enum class Region { render, traversal };

struct RegionCounts {
    EventCounts render, traversal;
};

// Hardware route: renders the frame twice, with the counters on for the whole of render() (its
// worker thread included), then only inside the accelerator calls. Throws cellrt::Error when the
// counters cannot be opened.
RegionCounts measure_with_counters(const Scene& scene, const Accelerator& accel, const RenderOptions& options);

// Software route: the work of the program that callgrind runs, with the options of callgrind_options().
// Instrumentation is on during render() alone, so loading the scene and building the structure run at
// valgrind's uninstrumented speed and are never counted.
void render_under_callgrind(const Scene& scene, const Accelerator& accel, const RenderOptions& options);
CallgrindOptions callgrind_options(Region region);

// `config` with its SIMD packet set named, so that the program callgrind runs traces with the same
// kernels as this one: under valgrind "auto" would choose another set, since valgrind runs no AVX-512
// (its processor model has none). "auto" that means AVX-512 here becomes "avx2", with one line in `note`;
// an explicit "avx512" is an error.
AccelConfig config_for_callgrind(AccelConfig config, std::string& note);

}  // namespace cellrt::profile
