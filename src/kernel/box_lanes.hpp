// A box and its centre in four float lanes (x, y, z and a spare), for builders whose passes over
// their records do the three axes' arithmetic at once: GCC's and Clang's generic vectors, SSE on
// x86-64, what the target has elsewhere. A record is anything that starts with its Box3 and has four
// more bytes after it (the SAH BIH's items, the wide BVH's references).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "cellrt/box.hpp"

namespace cellrt::detail {

typedef float F4 __attribute__((vector_size(16)));
typedef std::int32_t I4 __attribute__((vector_size(16)));

template <class Record>
constexpr bool kBoxFirst = offsetof(Record, box) == 0 && sizeof(Record) >= sizeof(Box3) + 4 && sizeof(Box3) == 24;

// The record's box corners, one unaligned load each; the lane past z is the next field (hi.x for
// `lo`; for `hi`, the record's next four bytes, zeroed: their bits could be a denormal, slow to add).
template <class Record>
F4 lanes_lo(const Record& r) {
    static_assert(kBoxFirst<Record>);
    F4 v;
    std::memcpy(&v, &r.box, sizeof v);
    return v;
}
template <class Record>
F4 lanes_hi(const Record& r) {
    static_assert(kBoxFirst<Record>);
    F4 v;
    std::memcpy(&v, reinterpret_cast<const char*>(&r.box) + 12, sizeof v);
    return std::bit_cast<F4>(std::bit_cast<I4>(v) & I4{-1, -1, -1, 0});
}
// Box3::center's arithmetic, so the same bits.
template <class Record>
F4 lanes_centre(const Record& r) {
    return (lanes_lo(r) + lanes_hi(r)) * 0.5f;
}

// AxisBins::bin (kernel/binning.hpp) on each lane: (x - origin) * scale, at most `last`, truncated,
// the same bins for every x and scale: where the product is not above 0 (NaN included, as 0 times an
// infinite scale or an infinite difference gives), bin 0. The SAH BIH's centres against their least
// one (an infinite centre, of coordinates past 1.7e38, made a NaN there that an unguarded conversion
// put far out of range: a crash).
inline I4 lane_bins_guarded(F4 x, F4 origin, F4 scale, F4 last) {
    const F4 k = (x - origin) * scale;
    const F4 clamped = last < k ? last : k;
    return __builtin_convertvector(k > 0.f ? clamped : F4{}, I4);
}

}  // namespace cellrt::detail
