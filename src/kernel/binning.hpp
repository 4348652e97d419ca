// Bins of equal width over one axis, for the builders' binned searches (the kd-tree's min-max bins,
// the wide BVH's centroid and spatial bins).
#pragma once

#include <algorithm>

namespace cellrt::detail {

// `count` bins over [lo, lo + count / scale]. bin(x) is monotone in x, so a box starting in a lower
// bin than a candidate plane starts before it, and one ending in a higher bin ends after it.
struct AxisBins {
    float lo = 0.f, scale = 0.f;  // scale 0: one bin holds everything
    int count = 1;

    AxisBins() = default;
    // `bins` bins over [lo, hi]; one bin where hi is not above lo.
    AxisBins(float lo_, float hi, int bins) : lo(lo_) {
        if (!(lo_ < hi)) return;
        scale = static_cast<float>(bins) / (hi - lo_);
        count = bins;
    }
    // Clamped as a float, before the conversion: a point at the far side gives `count`, and where
    // hi - lo is subnormal, scale is inf and the product inf or NaN, which no int holds.
    int bin(float x) const {
        const float k = (x - lo) * scale;
        return k > 0.f ? static_cast<int>(std::min(k, static_cast<float>(count - 1))) : 0;
    }
};

}  // namespace cellrt::detail
