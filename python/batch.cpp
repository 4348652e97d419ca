#include "batch.hpp"

#include <atomic>
#include <cmath>
#include <span>

#include "cellrt/timer.hpp"

namespace cellrt::python {
namespace {

bool finite3(const float* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

bool valid_input(const RayInput& in, std::size_t i) {
    return finite3(in.origins.data + 3 * i) && finite3(in.directions.data + 3 * i) && !std::isnan(in.tnear.at(i)) &&
           !std::isnan(in.tfar.at(i));
}

Ray ray_at(const RayInput& in, std::size_t i) {
    const float* o = in.origins.data + 3 * i;
    const float* d = in.directions.data + 3 * i;
    return Ray{{o[0], o[1], o[2]}, in.tnear.at(i), {d[0], d[1], d[2]}, in.tfar.at(i)};
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
        Ray rays[kChunk];
        for (std::size_t i = begin; i < end; ++i) {
            if (!valid_input(in, i)) {
                keep_lowest(first_invalid, i);
                return;
            }
            rays[i - begin] = ray_at(in, i);
        }
        trace(std::span<const Ray>(rays, end - begin), begin);
    });
    return first_invalid.load();
}

}  // namespace

RayInput ray_input(py::handle origins, py::handle directions, py::handle tnear, py::handle tfar) {
    RayInput in;
    in.origins = float_rows(origins, "origins", 3);
    in.directions = float_rows(directions, "directions", 3);
    if (in.origins.rows != in.directions.rows)
        throw py::value_error("origins has " + std::to_string(in.origins.rows) + " rays, directions " +
                              std::to_string(in.directions.rows));
    in.count = in.origins.rows;
    in.tnear = ray_bound(tnear, "tnear", in.count);
    in.tfar = ray_bound(tfar, "tfar", in.count);
    return in;
}

std::size_t intersect(const Accelerator& accel, const Team& team, const RayInput& in, HitOutput out) {
    return for_valid_chunks(team, in, [&](std::span<const Ray> rays, std::size_t begin) {
        Hit hits[kChunk];
        accel.intersect(rays, std::span<Hit>(hits, rays.size()));
        for (std::size_t k = 0; k < rays.size(); ++k) {
            const Hit& h = hits[k];
            out.t[begin + k] = h.t;
            out.prim[begin + k] = h.is_hit() ? static_cast<std::int64_t>(h.prim) : -1;
            out.u[begin + k] = h.u;
            out.v[begin + k] = h.v;
        }
    });
}

std::size_t occluded(const Accelerator& accel, const Team& team, const RayInput& in, std::uint8_t* out) {
    return for_valid_chunks(team, in, [&](std::span<const Ray> rays, std::size_t begin) {
        accel.occluded(rays, std::span<std::uint8_t>(out + begin, rays.size()));
    });
}

std::string invalid_ray_message(const RayInput& in, std::size_t i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (!finite3(in.origins.data + 3 * i)) return "origins" + at + " is not finite";
    if (!finite3(in.directions.data + 3 * i)) return "directions" + at + " is not finite";
    // A scalar bound was refused at once when NaN, so this one is an array's.
    return std::string(std::isnan(in.tnear.at(i)) ? "tnear" : "tfar") + at + " is NaN";
}

std::vector<double> native_intersect_seconds(const Accelerator& accel, const Team& team, const RayInput& in,
                                             int repeats) {
    std::vector<Ray> rays(in.count);
    for (std::size_t i = 0; i < in.count; ++i) rays[i] = ray_at(in, i);
    std::vector<Hit> hits(in.count);
    std::vector<double> seconds;
    for (int r = 0; r < repeats; ++r) {
        const Timer timer;
        team.for_chunks(in.count, [&](std::size_t begin, std::size_t end) {
            accel.intersect(std::span<const Ray>(rays.data() + begin, end - begin),
                            std::span<Hit>(hits.data() + begin, end - begin));
        });
        seconds.push_back(timer.seconds());
    }
    return seconds;
}

}  // namespace cellrt::python
