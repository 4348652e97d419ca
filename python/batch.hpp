// A batch of rays from numpy arrays traced on a team of threads: the batch cut into chunks of
// kChunk rays, each chunk's rays assembled from the arrays in place (origins, directions, bounds)
// and handed to the accelerator as one call, its answers written straight into the output arrays.
// Every function here runs without the GIL: it touches no Python object, only the arrays' memory.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "arrays.hpp"
#include "cellrt/accelerator.hpp"

namespace cellrt::python {

// Rays per accelerator call: 64 SIMD packets of 16 lanes, the most a packet kernel's entry-point
// search takes at once (src/packet/packet_kernels.inl), and few enough for the stack.
inline constexpr std::size_t kChunk = 1024;

// The threads a batch is traced on: all (TBB's default arena) or an arena of `threads`, never more
// than the machine has, as a build's (an arena of more printed TBB's warning on every batch; found by
// audit, 2026-12-07).
class Team {
public:
    explicit Team(unsigned threads) {
        if (threads > 0)
            arena_ = std::make_unique<tbb::task_arena>(
                static_cast<int>(std::min(threads, static_cast<unsigned>(tbb::info::default_concurrency()))));
    }

    // Calls f(begin, end) for every chunk of [0, count), on the team's threads; a batch of one chunk
    // runs on the calling thread alone. f must be safe to call at once on distinct chunks.
    template <class F>
    void for_chunks(std::size_t count, F&& f) const {
        if (count <= kChunk) {
            if (count > 0) f(std::size_t{0}, count);
            return;
        }
        const std::size_t chunks = (count + kChunk - 1) / kChunk;
        const auto run = [&] {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t c = r.begin(); c < r.end(); ++c) f(c * kChunk, std::min(count, (c + 1) * kChunk));
            });
        };
        if (arena_) arena_->execute(run);
        else run();
    }

private:
    std::unique_ptr<tbb::task_arena> arena_;
};

// The arguments of intersect() and occluded(), checked for shape and dtype (not yet for values).
struct RayInput {
    FloatRows origins, directions;
    Bound tnear, tfar;
    std::size_t count = 0;
};
RayInput ray_input(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar);

// Where closest hits go: count entries each.
struct HitOutput {
    float* t;
    std::int64_t* prim;
    float* u;
    float* v;
};

inline constexpr std::size_t kAllValid = static_cast<std::size_t>(-1);

// Trace the batch; return the index of the first ray with a NaN or infinite origin or direction or a
// NaN bound (kAllValid if none), whose chunk is then not traced: the caller refuses the whole batch.
std::size_t intersect(const Accelerator& accel, const Team& team, const RayInput& in, HitOutput out);
std::size_t occluded(const Accelerator& accel, const Team& team, const RayInput& in, std::uint8_t* out);

// The ValueError's message for ray `index`, which intersect() or occluded() found invalid.
std::string invalid_ray_message(const RayInput& in, std::size_t index);

// The C++ side of the benchmark: the batch assembled into Ray records once, then traced `repeats`
// times with the same chunks and threads into a Hit array kept between them, as a C++ program would;
// the seconds of each trace, wall-clock or (`cpu`) the process's CPU time, all threads together.
// Expects valid rays.
std::vector<double> native_intersect_seconds(const Accelerator& accel, const Team& team, const RayInput& in,
                                             int repeats, bool cpu);

}  // namespace cellrt::python
