// Perfect splits (Wald & Havran 2006, section 4.1): a triangle clipped to a child cell, in double
// precision, its box rounded outward to floats, so that child boxes are tight and still conservative.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "cellrt/box.hpp"
#include "cellrt/triangle.hpp"
#include "kernel/outward.hpp"

namespace cellrt::detail::kdbuild {

// A triangle clipped to axis-aligned half-spaces one at a time (Sutherland-Hodgman, in double
// precision). Cutting a convex polygon by a plane adds at most one vertex: 3 + 6 planes. Each cut
// writes the new polygon into the other of two buffers rather than copying it back, a copy that
// would stall on reading vertices just written piecewise.
class ClippedPolygon {
public:
    explicit ClippedPolygon(const Triangle& t) {
        P* v = buffers_[0];
        v[0] = {t.v0.x, t.v0.y, t.v0.z};
        v[1] = {t.v1.x, t.v1.y, t.v1.z};
        v[2] = {t.v2.x, t.v2.y, t.v2.z};
        n_ = 3;
    }
    ClippedPolygon(const ClippedPolygon& other) : n_(other.n_) {
        std::copy_n(other.buffers_[other.current_], kMaxVertices, buffers_[0]);
    }
    ClippedPolygon& operator=(const ClippedPolygon& other) {
        n_ = other.n_;
        current_ = 0;
        std::copy_n(other.buffers_[other.current_], kMaxVertices, buffers_[0]);
        return *this;
    }
    ClippedPolygon() = default;  // empty, for split() to fill

    // Keeps the part with c[a] >= plane (`keep_above`) or c[a] <= plane.
    template <bool keep_above>
    void clip(int a, double plane) {
        const P* v = buffers_[current_];
        bool in[kMaxVertices];
        int inside = 0;
        for (int i = 0; i < n_; ++i) {
            in[i] = keep_above ? v[i].c[a] >= plane : v[i].c[a] <= plane;
            inside += in[i];
        }
        if (inside == n_) return;
        // Every vertex and every edge's crossing point is written, and kept by moving on or not:
        // which edges cross is unpredictable, and a branch on it costs more than the arithmetic.
        P* kept = buffers_[current_ ^ 1];
        int m = 0;
        for (int i = 0; i < n_; ++i) {
            const int j = i + 1 == n_ ? 0 : i + 1;
            const P& cur = v[i];
            const P& nxt = v[j];
            kept[m] = cur;
            m += in[i];
            const double s = (plane - cur.c[a]) / (nxt.c[a] - cur.c[a]);
            P& x = kept[m];
            for (int k = 0; k < 3; ++k) x.c[k] = cur.c[k] + s * (nxt.c[k] - cur.c[k]);
            x.c[a] = plane;
            m += in[i] != in[j];
        }
        n_ = m;
        current_ ^= 1;
    }
    // clip<true>(a, plane) of this polygon, and clip<false>(a, plane) of it written to `below`, in
    // one pass: each edge's crossing is computed once for both sides, with the same operands and so
    // the same bits as either clip would give it. (A side that keeps every vertex gets them all, in
    // order: the polygon a clip that returns early leaves.)
    void split(int a, double plane, ClippedPolygon& below) {
        const P* v = buffers_[current_];
        bool above_in[kMaxVertices], below_in[kMaxVertices];
        for (int i = 0; i < n_; ++i) {
            above_in[i] = v[i].c[a] >= plane;
            below_in[i] = v[i].c[a] <= plane;
        }
        P* kept_above = buffers_[current_ ^ 1];
        P* kept_below = below.buffers_[0];
        int m_above = 0, m_below = 0;
        for (int i = 0; i < n_; ++i) {
            const int j = i + 1 == n_ ? 0 : i + 1;
            const P& cur = v[i];
            const P& nxt = v[j];
            kept_above[m_above] = cur;
            m_above += above_in[i];
            kept_below[m_below] = cur;
            m_below += below_in[i];
            const double s = (plane - cur.c[a]) / (nxt.c[a] - cur.c[a]);
            P x;
            for (int k = 0; k < 3; ++k) x.c[k] = cur.c[k] + s * (nxt.c[k] - cur.c[k]);
            x.c[a] = plane;
            kept_above[m_above] = x;
            m_above += above_in[i] != above_in[j];
            kept_below[m_below] = x;
            m_below += below_in[i] != below_in[j];
        }
        below.n_ = m_below;
        below.current_ = 0;
        n_ = m_above;
        current_ ^= 1;
    }

    // Clips to the slab of `cell` on axis `a`, skipping a plane that the triangle's box `inside` lies
    // strictly within: it cuts no vertex. (Vertices made by earlier cuts may stray from that box by a
    // few roundings in double, far less than the float step between box and plane unless coordinates
    // differ by many orders of magnitude; a cut skipped there would only leave the box a little larger,
    // still conservative.)
    [[gnu::always_inline]] void clip_to_slab(int a, const Box3& cell, const Box3& inside) {
        if (!(inside.lo[a] > cell.lo[a])) clip<true>(a, cell.lo[a]);
        if (!(inside.hi[a] < cell.hi[a])) clip<false>(a, cell.hi[a]);
    }

    // Bounds rounded outward and cut to `cell`; empty when nothing is left.
    [[gnu::always_inline]] Box3 bounds(const Box3& cell) const {
        if (n_ == 0) return Box3::empty();
        const P* v = buffers_[current_];
        double lo[3], hi[3];
        for (int k = 0; k < 3; ++k) lo[k] = hi[k] = v[0].c[k];
        for (int i = 1; i < n_; ++i)
            for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[i].c[k]), hi[k] = std::max(hi[k], v[i].c[k]);
        Box3 b;
        for (int k = 0; k < 3; ++k) {
            b.lo[k] = std::max(float_below(lo[k]), cell.lo[k]);
            b.hi[k] = std::min(float_above(hi[k]), cell.hi[k]);
        }
        return b;
    }

private:
    static constexpr int kMaxVertices = 9;
    struct P {
        double c[3];
    };
    P buffers_[2][kMaxVertices + 1];  // one spare slot for the last unconditional write
    int current_ = 0;
    int n_ = 0;
};

// Bounds of the parts of `tri` in the two children of `cell` split at `pos` on `axis`: each is the
// triangle clipped to the child cell's six planes in the order x-lo, x-hi, y-lo, ..., z-hi. The two
// children share the planes before the split axis, so that prefix is clipped once for both; planes
// that cut no vertex of the triangle's box are skipped (the same polygon: see clip_to_slab).
inline std::pair<Box3, Box3> clipped_child_bounds(const Triangle& tri, const Box3& cell, int axis, float pos) {
    Box3 lcell = cell, rcell = cell;
    lcell.hi[axis] = rcell.lo[axis] = pos;
    const Box3 inside = tri.bounds();
    ClippedPolygon right(tri);
    for (int a = 0; a < axis; ++a) right.clip_to_slab(a, cell, inside);
    ClippedPolygon left;
    if (inside.lo[axis] > cell.lo[axis] && !(inside.lo[axis] > pos) && !(inside.hi[axis] < pos)) {
        // The left side's first cut on the split axis is the plane, as the right side's is: one
        // pass for both (the common case: a straddler that does not reach the cell's low plane).
        right.split(axis, pos, left);
        if (!(inside.hi[axis] < cell.hi[axis])) right.clip<false>(axis, cell.hi[axis]);
    } else {
        left = right;
        left.clip_to_slab(axis, lcell, inside);
        right.clip_to_slab(axis, rcell, inside);
    }
    for (int a = axis + 1; a < 3; ++a) {
        left.clip_to_slab(a, cell, inside);
        right.clip_to_slab(a, cell, inside);
    }
    return {left.bounds(lcell), right.bounds(rcell)};
}

}  // namespace cellrt::detail::kdbuild
