#include "batch.hpp"

#include <atomic>
#include <cmath>
#include <cstring>
#include <span>

#include <time.h>

#include "cellrt/error.hpp"
#include "core/timer.hpp"

namespace cellrt::python {
namespace {

bool finite3(const float* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

// Whether all n floats are finite (exponent not all ones), in one pass the compiler vectorises.
bool all_finite(const float* p, std::size_t n) {
    std::uint32_t bad = 0;
    for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, p + i, sizeof bits);
        bad |= static_cast<std::uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
    }
    return bad == 0;
}

bool any_nan(const float* p, std::size_t n) {
    std::uint32_t nan = 0;
    for (std::size_t i = 0; i < n; ++i) nan |= static_cast<std::uint32_t>(p[i] != p[i]);
    return nan != 0;
}

bool valid_input(const RayInput& in, std::size_t i) {
    return finite3(in.origins.data + 3 * i) && finite3(in.directions.data + 3 * i) && !std::isnan(in.tnear.at(i)) &&
           !std::isnan(in.tfar.at(i));
}

// Rays [begin, end) of the arrays, read in place into `rays`, or false when one of them is invalid.
// The pointers are held in locals: a store to a Ray's floats could otherwise alias a scalar bound.
bool assemble(const RayInput& in, std::size_t begin, std::size_t end, Ray* rays) {
    const std::size_t n = end - begin;
    const float* o = in.origins.data + 3 * begin;
    const float* d = in.directions.data + 3 * begin;
    const float* tnear = in.tnear.per_ray() ? in.tnear.values.data + begin : nullptr;
    const float* tfar = in.tfar.per_ray() ? in.tfar.values.data + begin : nullptr;
    if (!all_finite(o, 3 * n) || !all_finite(d, 3 * n) || (tnear && any_nan(tnear, n)) || (tfar && any_nan(tfar, n)))
        return false;
    const float tnear0 = in.tnear.scalar, tfar0 = in.tfar.scalar;
    for (std::size_t k = 0; k < n; ++k, o += 3, d += 3)
        rays[k] = Ray{{o[0], o[1], o[2]}, tnear ? tnear[k] : tnear0, {d[0], d[1], d[2]}, tfar ? tfar[k] : tfar0};
    return true;
}

Ray ray_at(const RayInput& in, std::size_t i) {
    const float* o = in.origins.data + 3 * i;
    const float* d = in.directions.data + 3 * i;
    return Ray{{o[0], o[1], o[2]}, in.tnear.at(i), {d[0], d[1], d[2]}, in.tfar.at(i)};
}

// CLOCK_PROCESS_CPUTIME_ID, Python's time.process_time().
double process_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void keep_lowest(std::atomic<std::size_t>& first, std::size_t index) {
    std::size_t seen = first.load(std::memory_order_relaxed);
    while (index < seen && !first.compare_exchange_weak(seen, index, std::memory_order_relaxed)) {
    }
}

// Assembles each chunk's rays and calls trace(rays, begin) for the chunks whose rays are all valid.
template <class Trace>
std::size_t for_valid_chunks(const Team& team, const RayInput& in, Trace&& trace) {
    std::atomic<std::size_t> first_invalid{kAllValid};
    team.for_chunks(in.count, [&](std::size_t begin, std::size_t end) {
        // Kept per thread: a chunk's buffer is written, never initialised first.
        thread_local std::vector<Ray> rays(kChunk);
        if (!assemble(in, begin, end, rays.data())) {
            std::size_t i = begin;
            while (valid_input(in, i)) ++i;
            keep_lowest(first_invalid, i);
            return;
        }
        trace(std::span<const Ray>(rays.data(), end - begin), begin);
    });
    return first_invalid.load();
}

}  // namespace

RayInput ray_input(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar) {
    RayInput in;
    // Every length compared before the rays are copied: a mismatch is named, where a copy of a huge
    // view would first run out of memory.
    const py::array o = row_array(origins, "origins", 3), d = row_array(directions, "directions", 3);
    if (o.shape(0) != d.shape(0))
        throw py::value_error("origins has " + std::to_string(o.shape(0)) + " rays, directions " +
                              std::to_string(d.shape(0)));
    in.count = static_cast<std::size_t>(o.shape(0));
    in.tnear = ray_bound(tnear, "tnear", in.count, Inward::up);
    in.tfar = ray_bound(tfar, "tfar", in.count, Inward::down);
    in.origins = float_rows(o, "origins");
    in.directions = float_rows(d, "directions");
    return in;
}

namespace {

// for_valid_chunks for an accelerator that may refuse rays (Embree's domain): a chunk holding one is
// not traced, and once every chunk is done the lowest such chunk is checked again, so that the error
// names the call's first refused ray by its index in the call, whichever thread met which chunk first.
// A chunk with an invalid ray is neither traced nor checked: the rays before the first invalid one
// in its chunk are checked here, so that the earlier of the first invalid ray and the first refused
// one is the one named (found by audit, 2026-12-07: Embree's refusal of ray 3000 was raised over an
// invalid ray 100). Chunks start at multiples of kChunk (Team::for_chunks).
template <class Trace>
std::size_t for_admitted_chunks(const Accelerator& accel, const Team& team, const RayInput& in, Trace&& trace) {
    if (!accel.refuses_rays()) return for_valid_chunks(team, in, trace);
    std::atomic<std::size_t> refused{kAllValid};
    const std::size_t first_invalid = for_valid_chunks(team, in, [&](std::span<const Ray> rays, std::size_t begin) {
        try {
            accel.check_rays(rays, begin);
        } catch (const Error&) {
            keep_lowest(refused, begin);
            return;
        }
        trace(rays, begin);
    });
    const auto check = [&](std::size_t begin, std::size_t end) {  // throws, naming the ray
        std::vector<Ray> rays(end - begin);
        assemble(in, begin, end, rays.data());
        accel.check_rays(rays, begin);
    };
    if (const std::size_t begin = refused.load(); begin != kAllValid && begin < first_invalid)
        check(begin, std::min(in.count, begin + kChunk));
    if (first_invalid != kAllValid) check(first_invalid - first_invalid % kChunk, first_invalid);
    return first_invalid;
}

}  // namespace

std::size_t intersect(const Accelerator& accel, const Team& team, const RayInput& in, HitOutput out) {
    return for_admitted_chunks(accel, team, in, [&](std::span<const Ray> rays, std::size_t begin) {
        thread_local std::vector<Hit> hits(kChunk);
        accel.intersect(rays, std::span<Hit>(hits.data(), rays.size()));
        float* t = out.t + begin;
        std::int64_t* prim = out.prim + begin;
        float* u = out.u + begin;
        float* v = out.v + begin;
        for (std::size_t k = 0; k < rays.size(); ++k) {
            const Hit& h = hits[k];
            t[k] = h.t;
            prim[k] = h.is_hit() ? static_cast<std::int64_t>(h.prim) : -1;
            u[k] = h.u;
            v[k] = h.v;
        }
    });
}

std::size_t occluded(const Accelerator& accel, const Team& team, const RayInput& in, std::uint8_t* out) {
    return for_admitted_chunks(accel, team, in, [&](std::span<const Ray> rays, std::size_t begin) {
        accel.occluded(rays, std::span<std::uint8_t>(out + begin, rays.size()));
    });
}

std::string invalid_ray_message(const RayInput& in, std::size_t i) {
    const std::string at = "[" + std::to_string(i) + "]";
    // The values are named only where they were finite as given (beyond float32's range).
    const auto named = [&](const FloatRows& rows, const char* name) {
        return beyond_float32(rows, py::int_(i), name + at).value_or(name + at + " is not finite");
    };
    if (!finite3(in.origins.data + 3 * i)) return named(in.origins, "origins");
    if (!finite3(in.directions.data + 3 * i)) return named(in.directions, "directions");
    // A scalar bound was refused at once when NaN, so this one is an array's.
    return std::string(std::isnan(in.tnear.at(i)) ? "tnear" : "tfar") + at + " is NaN";
}

std::vector<double> native_intersect_seconds(const Accelerator& accel, const Team& team, const RayInput& in,
                                             int repeats, bool cpu) {
    std::vector<Ray> rays(in.count);
    for (std::size_t i = 0; i < in.count; ++i) rays[i] = ray_at(in, i);
    std::vector<Hit> hits(in.count);
    std::vector<double> seconds;
    for (int r = 0; r < repeats; ++r) {
        const Timer timer;
        const double cpu_start = process_cpu_seconds();
        team.for_chunks(in.count, [&](std::size_t begin, std::size_t end) {
            accel.intersect(std::span<const Ray>(rays.data() + begin, end - begin),
                            std::span<Hit>(hits.data() + begin, end - begin));
        });
        seconds.push_back(cpu ? process_cpu_seconds() - cpu_start : timer.seconds());
    }
    return seconds;
}

}  // namespace cellrt::python
