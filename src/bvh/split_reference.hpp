// Spatial splits' cut of one reference (Stich, Friedrich, Dietrich, "Spatial Splits in Bounding
// Volume Hierarchies", HPG 2009, section 4.2): the bounds of a triangle's parts on either side of a
// plane, conservative in float. Used by the BVH's builder (bvh_build.cpp); a header of its own so
// that tests can hold it to exact arithmetic.
#pragma once

#include <cmath>
#include <utility>

#include "cellrt/box.hpp"
#include "cellrt/triangle.hpp"
#include "kernel/outward.hpp"

namespace cellrt::detail {

// The bounds of the parts of `tri` on either side of the plane c[axis] = pos, each cut to `box`
// (Stich et al. section 4.2, "split the reference"). The edges' crossings are computed in double,
// widened by a bound of their rounding error and rounded outward to floats, so that both boxes
// stay conservative; the crossings lie on the plane, which bounds each side exactly.
inline std::pair<Box3, Box3> split_reference(const Triangle& tri, const Box3& box, int axis, float pos) {
    const Vec3* v[3] = {&tri.v0, &tri.v1, &tri.v2};
    Box3 left, right;
    for (int i = 0; i < 3; ++i) {
        const Vec3& p = *v[i];
        const Vec3& q = *v[i == 2 ? 0 : i + 1];
        if (p[axis] <= pos) left.extend(p);
        if (p[axis] >= pos) right.extend(p);
        if (!((p[axis] < pos && q[axis] > pos) || (p[axis] > pos && q[axis] < pos))) continue;
        const double s = (double(pos) - p[axis]) / (double(q[axis]) - p[axis]);
        Box3 crossing;
        for (int k = 0; k < 3; ++k) {
            if (k == axis) {
                crossing.lo[k] = crossing.hi[k] = pos;
                continue;
            }
            const double x = p[k] + s * (double(q[k]) - p[k]);
            const double err = (std::abs(double(p[k])) + std::abs(double(q[k]))) * 0x1p-48;
            crossing.lo[k] = float_below(x - err);
            crossing.hi[k] = float_above(x + err);
        }
        left.extend(crossing);
        right.extend(crossing);
    }
    return {intersection(left, box), intersection(right, box)};
}

}  // namespace cellrt::detail
