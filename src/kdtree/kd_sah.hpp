// The surface area heuristic of a kd-tree split (Wald & Havran 2006, section 3) and the search for
// the cheapest candidate.
#pragma once

#include <cmath>
#include <limits>

#include "cellrt/box.hpp"
#include "kd_tree.hpp"

namespace cellrt::detail::kdbuild {

// The SAH of one candidate split of `cell` (W&H section 3): probabilities are the children's
// surface areas over the parent's, from two per-axis factors precomputed per cell.
class SahCost {
public:
    SahCost(const Box3& cell, const KdBuildParams& p) : p_(p), empty_factor_(1.0 - p.empty_bonus) {
        const double e[3] = {double(cell.hi.x) - cell.lo.x, double(cell.hi.y) - cell.lo.y,
                             double(cell.hi.z) - cell.lo.z};
        for (int a = 0; a < 3; ++a) {
            const double b = e[(a + 1) % 3], c = e[(a + 2) % 3];
            constant_[a] = b * c;
            linear_[a] = b + c;
            lo_[a] = cell.lo[a];
            hi_[a] = cell.hi[a];
        }
        half_area_ = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
        scaled_reciprocal_ = p.intersection_cost / half_area_;
    }
    bool splittable() const { return half_area_ > 0.0; }
    double leaf(std::size_t n) const { return p_.intersection_cost * static_cast<double>(n); }
    // Half the surface areas of the two children: the numerators of their probabilities.
    std::pair<double, double> areas(int a, float pos) const {
        const double wl = double(pos) - lo_[a], wr = hi_[a] - pos;
        return {constant_[a] + wl * linear_[a], constant_[a] + wr * linear_[a]};
    }
    // areas() at any point x of the axis, for bounds of the cost between candidates.
    std::pair<double, double> areas_at(int a, double x) const {
        const double wl = x - lo_[a], wr = hi_[a] - x;
        return {constant_[a] + wl * linear_[a], constant_[a] + wr * linear_[a]};
    }
    // Probabilities that a ray through the cell passes through the left and the right child.
    std::pair<double, double> probabilities(int a, float pos) const {
        const auto [al, ar] = areas(a, pos);
        return {al / half_area_, ar / half_area_};
    }
    double split(std::pair<double, double> areas, std::ptrdiff_t nl, std::ptrdiff_t nr) const {
        const double pl = areas.first / half_area_, pr = areas.second / half_area_;
        return with_bonus(p_.traversal_cost + p_.intersection_cost * (pl * double(nl) + pr * double(nr)), nl, nr);
    }
    // split() without its two divisions: a multiplication by a reciprocal instead. Each of the two
    // is at most eight roundings from the real value of the expression, so with nonnegative terms
    // both lie within a relative 8 * 2^-53 = 2^-50 of it.
    double estimate(std::pair<double, double> areas, std::ptrdiff_t nl, std::ptrdiff_t nr) const {
        const double weighted = areas.first * double(nl) + areas.second * double(nr);
        return with_bonus(p_.traversal_cost + scaled_reciprocal_ * weighted, nl, nr);
    }
    // Whether every term of split() is nonnegative, so that relative rounding errors do not grow.
    bool nonnegative() const {
        return p_.traversal_cost >= 0.0 && p_.intersection_cost >= 0.0 && p_.empty_bonus >= 0.0 && p_.empty_bonus <= 1.0;
    }

private:
    double with_bonus(double cost, std::ptrdiff_t nl, std::ptrdiff_t nr) const {
        return nl == 0 || nr == 0 ? cost * empty_factor_ : cost;
    }

    const KdBuildParams& p_;
    double empty_factor_;  // 1 - empty_bonus
    double lo_[3], hi_[3];  // the cell's planes
    double constant_[3], linear_[3], half_area_, scaled_reciprocal_;
};

struct Split {
    double cost = std::numeric_limits<double>::infinity();
    int axis = -1;
    float pos = 0.f;
    bool planar_left = true;  // where triangles lying in the plane go
};

// The cheapest of the candidate splits offered; the first of equal costs wins.
//
// The exact cost takes two divisions, the sweep's largest expense. So candidates are screened by
// SahCost::estimate(): it and the exact cost are both within a relative 2^-50 of the real value
// (all magnitudes come from float extents, far from double underflow and overflow), so a candidate
// whose estimate is not below best * (1 + 2^-40) costs more than the best and is dropped unseen.
// The choice is exactly that of costing every candidate exactly.
class SplitSearch {
public:
    explicit SplitSearch(const SahCost& sah) : sah_(sah), screens_(sah.nonnegative()) {}

    // Whether a candidate with this estimate may be cheaper than the best.
    bool may_improve(double estimate) const { return estimate < bound_; }
    [[gnu::always_inline]] void offer(int axis, float pos, std::pair<double, double> areas, std::ptrdiff_t nl, std::ptrdiff_t nr,
               bool planar_left) {
        if (!may_improve(sah_.estimate(areas, nl, nr))) return;
        const double cost = sah_.split(areas, nl, nr);
        if (!(cost < best_.cost)) return;
        best_ = {cost, axis, pos, planar_left};
        if (screens_) bound_ = cost * (1.0 + 0x1p-40);
    }
    const Split& best() const { return best_; }

private:
    const SahCost& sah_;
    bool screens_;
    Split best_;
    double bound_ = std::numeric_limits<double>::infinity();
};

}  // namespace cellrt::detail::kdbuild
