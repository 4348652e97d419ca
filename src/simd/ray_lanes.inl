// A batch's rays in SIMD lanes, each with the single-ray kernels' set-up (TraversalRay,
// kernel/traversal.hpp, and WatertightRay, triangle.hpp) made in its lane with their operations in
// their order, so that each lane holds its ray's very bits: one vector division or square root does
// the work of kLanes rays' (seven divisions and two square roots a ray), and the scalar set-up's
// branches (the dominant axis and its sign, mispredicted on incoherent rays) become selects. Used by
// the SIMD packets (packet/packet_kernels.inl) and by the wide BVH's packets, paired walks and
// streams (bvh/bvh_kernels.inl).
//
// No include guard: included after simd/lanes.inl, once per namespace of lanes.

inline F abs_lanes(F x) { return (F)((I)x & splat_i(0x7fffffff)); }  // std::fabs clears the sign bit
inline F max_lanes(F a, F b) { return select(a < b, b, a); }        // std::max's choice, lane by lane
// det_in_range (triangle.hpp), lane by lane: the watertight test's determinant a normal float.
inline I det_in_range_lanes(F det) {
    const F a = abs_lanes(det);
    return (a >= splat(kLeastNormal)) & (a < splat(kInfinity));
}

// The lanes `lanes` (bit i: lane i) of an ill-conditioned hit, refined one by one (refined_t), as
// the scalar test refines its hit; a lane whose refined t is not finite is no hit. The lanes of
// `tiny_only` were taken for a T of zero or subnormal alone: each is refined only where its terms
// underflowed (t_underflowed, on the terms recomputed in the lane's order; the vector test keeps
// them out of its registers). Out of line, so that the rare case does not crowd the test's registers.
template <class Coord>
[[gnu::noinline]] void refine_lanes(Coord coord, unsigned lanes, unsigned tiny_only, const F& eu, const F& ev,
                                    const F& ew, const F& a_kz, const F& b_kz, const F& c_kz, const F& big_t,
                                    const F& ox, const F& oy, const F& oz, const F& sx, const F& sy, const F& sz,
                                    F& t, F& u, F& v, I& hit) {
    for (; lanes; lanes &= lanes - 1) {
        const int i = __builtin_ctz(lanes);
        if ((tiny_only >> i) & 1) {
            const float az = sz[i] * a_kz[i], bz = sz[i] * b_kz[i], cz = sz[i] * c_kz[i];
            if (!t_underflowed(big_t[i], eu[i] * az, ev[i] * bz, ew[i] * cz)) continue;
        }
        float x[3], y[3], z[3];
        for (int k = 0; k < 3; ++k) {
            x[k] = coord(k, 0)[i];
            y[k] = coord(k, 1)[i];
            z[k] = coord(k, 2)[i];
        }
        float rt, ru, rv;
        if (refined_t(x, y, z, ox[i], oy[i], oz[i], sx[i], sy[i], sz[i], rt, ru, rv)) {
            t[i] = rt;
            u[i] = ru;
            v[i] = rv;
        } else {
            hit[i] = 0;
        }
    }
}

// The watertight test (triangle.hpp) in lanes: coord(k, role) gives vertex k's coordinate on each
// lane's ray's kx, ky or kz axis (role 0, 1, 2), read where it is used; (ox, oy, oz) the ray's origin
// on those axes and (sx, sy, sz) its shear. Each lane runs the scalar test's operations in their
// order, so t, u and v carry its bits; an edge function of exactly zero (a ray through an edge or a
// vertex) is recomputed in double precision as the scalar test does, and so is the t of an
// ill-conditioned hit. Returns the lanes of `used` whose ray meets its triangle; t's finiteness is
// left to the callers' bounds, which are finite floats (kernel/traversal.hpp). The lanes by
// reference, read where they are used: taken by value, they were all loaded before the test and the
// AVX2 kernels spilled. One copy for the kd-tree's and the BIH's packets (packet_kernels.inl), the
// wide BVH's leaves (bvh_kernels.inl) and its packets' leaves (bvh_packet.inl).
template <class Coord>
[[gnu::always_inline]] inline I watertight_in_lanes(Coord&& coord, const F& ox, const F& oy, const F& oz, const F& sx,
                                                    const F& sy, const F& sz, const I& used, F& t, F& u, F& v) {
    const F a_kz = coord(0, 2) - oz, b_kz = coord(1, 2) - oz, c_kz = coord(2, 2) - oz;
    const F ax = (coord(0, 0) - ox) - sx * a_kz, ay = (coord(0, 1) - oy) - sy * a_kz;
    const F bx = (coord(1, 0) - ox) - sx * b_kz, by = (coord(1, 1) - oy) - sy * b_kz;
    const F cx = (coord(2, 0) - ox) - sx * c_kz, cy = (coord(2, 1) - oy) - sy * c_kz;
    F eu = cx * by - cy * bx;
    F ev = ax * cy - ay * cx;
    F ew = bx * ay - by * ax;
    const I zero = used & ((eu == 0.f) | (ev == 0.f) | (ew == 0.f));
    if (any(zero)) {
        for (int i = 0; i < kLanes; ++i) {
            if (zero[i] == 0) continue;
            eu[i] = edge_in_double(cx[i], by[i], cy[i], bx[i]);
            ev[i] = edge_in_double(ax[i], cy[i], ay[i], cx[i]);
            ew[i] = edge_in_double(bx[i], ay[i], by[i], ax[i]);
        }
    }
    const I negative = (eu < 0.f) | (ev < 0.f) | (ew < 0.f);
    const I positive = (eu > 0.f) | (ev > 0.f) | (ew > 0.f);
    const F det = eu + ev + ew;
    const F az = sz * a_kz, bz = sz * b_kz, cz = sz * c_kz;
    const F big_t = eu * az + ev * bz + ew * cz;
    const F inv_det = splat(1.f) / det;
    t = big_t * inv_det;
    u = ev * inv_det;
    v = ew * inv_det;
    I hit = used & ~(negative & positive) & det_in_range_lanes(det);
    // Ill-conditioned hits with a finite t (triangle.hpp, ill_conditioned) are taken again as the
    // scalar test takes them, out of line; only where some lane hits. The operands are not NaN in
    // a lane that hits, where the maxima and minima are std::max's and std::min's.
    if (any(hit)) {
        const F lateral = lane_max_f(lane_max_f(lane_max_f(abs_lanes(ax), abs_lanes(bx)), abs_lanes(cx)),
                                     lane_max_f(lane_max_f(abs_lanes(ay), abs_lanes(by)), abs_lanes(cy)));
        const F depth = lane_max_f(lane_max_f(a_kz, b_kz), c_kz) - lane_min_f(lane_min_f(a_kz, b_kz), c_kz);
        const I ratio = (lateral * depth) * splat(1.f / kIllConditioned) > abs_lanes(det);
        // A T of zero or subnormal (triangle.hpp, t_underflowed): its terms are looked at out of line.
        const I ill = hit & (abs_lanes(t) < splat(kInfinity)) & (ratio | (abs_lanes(big_t) < splat(kLeastNormal)));
        if (const unsigned lanes = bits(ill)) [[unlikely]]
            refine_lanes(coord, lanes, bits(ill & ~ratio), eu, ev, ew, a_kz, b_kz, c_kz, big_t, ox, oy, oz, sx, sy, sz,
                         t, u, v, hit);
    }
    return hit;
}

// TraversalRay's set-up of rays [0, n) of a batch (n <= kLanes), tnear and tfar clamped to the
// finite floats. Lanes of invalid rays (ray.hpp) and lanes past n hold a harmless ray (origin 0,
// direction (1, 1, 1)) and are not in `valid`.
struct RayLanes {
    F org[3], dir[3], inv[3];
    I negative[3];  // the direction's sign bit per axis, -0 included (std::signbit): enters by the hi plane
    F tnear, tfar, margin;
    F axis_margin[3];  // kernel/traversal.hpp's axis_margins
    I valid;
};

inline RayLanes load_ray_lanes(const Ray* rays, std::size_t n, const Box3& scene) {
    RayLanes L;
    F o[3], d[3];
    for (int a = 0; a < 3; ++a) o[a] = d[a] = splat(0.f);
    L.tnear = L.tfar = splat(0.f);
    I loaded = splat_i(0);
    for (std::size_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) o[a][i] = rays[i].org[a], d[a][i] = rays[i].dir[a];
        L.tnear[i] = rays[i].tnear;
        L.tfar[i] = rays[i].tfar;
        loaded[i] = -1;
    }
    // is_valid (ray.hpp): finite origin and direction (x - x is 0 only for finite x), a direction
    // with a component of at least 2^-126, tnear <= tfar, no NaN bound, tnear below +inf.
    I finite = loaded;
    for (int a = 0; a < 3; ++a) finite &= ((o[a] - o[a]) == 0.f) & ((d[a] - d[a]) == 0.f);
    const F least = splat(kLeastNormal);
    I normal[3];
    for (int a = 0; a < 3; ++a) normal[a] = abs_lanes(d[a]) >= least;
    const I normal_dir = normal[0] | normal[1] | normal[2];
    L.valid = finite & normal_dir & ~(L.tnear > L.tfar) & (L.tnear < splat(kInfinity)) & (L.tfar == L.tfar);
    // The bounds within the finite floats: a hit's t is finite (triangle.hpp), and the packets'
    // triangle test and the BVH's leaf lanes leave that to these bounds (and the queries made from
    // them, kernel/traversal.hpp) rather than testing each lane's t.
    L.tnear = max_lanes(L.tnear, splat(-kLargestFloat));
    L.tfar = select(L.tfar > splat(kLargestFloat), splat(kLargestFloat), L.tfar);
    F reach[3];
    for (int a = 0; a < 3; ++a) {
        L.org[a] = select(L.valid, o[a], splat(0.f));
        // traced_direction (ray.hpp): a subnormal component is a zero of its sign.
        L.dir[a] = select(L.valid, select(normal[a], d[a], (F)((I)d[a] & splat_i(INT32_MIN))), splat(1.f));
        L.inv[a] = splat(1.f) / L.dir[a];
        L.negative[a] = (I)L.dir[a] < 0;
        reach[a] = max_lanes(abs_lanes(splat(scene.lo[a]) - L.org[a]), abs_lanes(splat(scene.hi[a]) - L.org[a]));
    }
    const F reach_length = sqrt_lanes(reach[0] * reach[0] + reach[1] * reach[1] + reach[2] * reach[2]);
    const F dir_length = sqrt_lanes(L.dir[0] * L.dir[0] + L.dir[1] * L.dir[1] + L.dir[2] * L.dir[2]);
    const F m = splat(kMarginScale) * reach_length / dir_length;
    L.margin = max_lanes(m, splat(kMarginFloor));
    // traversal_margin, lane by lane: where the direct margin does not hold, the rescaled one.
    const I direct = (m > splat(0.f)) & (m < splat(kInfinity));
    if (any(~direct))
        for (std::size_t i = 0; i < kLanes; ++i)
            if (!direct[i])
                L.margin[i] = traversal_margin_rescaled({reach[0][i], reach[1][i], reach[2][i]},
                                                        {L.dir[0][i], L.dir[1][i], L.dir[2][i]});
    // axis_margins, lane by lane in its operations and order.
    const F dir_max = max_lanes(abs_lanes(L.dir[0]), max_lanes(abs_lanes(L.dir[1]), abs_lanes(L.dir[2])));
    const F spread = splat(kAcrossScale) * dir_max;
    for (int a = 0; a < 3; ++a) {
        const F x = L.margin * (spread * abs_lanes(L.inv[a]));
        L.axis_margin[a] = select(x < splat(kLargestFloat), select(x > L.margin, x, L.margin), splat(kLargestFloat));
    }
    return L;
}

// The lane of each ray's axis k (0, 1 or 2) of v.
inline F pick_axis(const F (&v)[3], I k) { return select(k == 0, v[0], select(k == 1, v[1], v[2])); }

// WatertightRay's set-up of the rays in `L`: kz the axis of the largest |d| (ties to the lower axis,
// as max_axis), kx and ky the next two, swapped where d[kz] is negative; the shear and the origin in
// that axis order.
struct WatertightLanes {
    F org[3], shear[3];  // the origin's kx, ky, kz coordinates; sx, sy, sz
    I kx, ky, kz;
    I swapped;

    explicit WatertightLanes(const RayLanes& L) {
        const F m0 = abs_lanes(L.dir[0]), m1 = abs_lanes(L.dir[1]), m2 = abs_lanes(L.dir[2]);
        kz = select(m0 >= m1, select(m0 >= m2, splat_i(0), splat_i(2)), select(m1 >= m2, splat_i(1), splat_i(2)));
        const I next = select(kz == 2, splat_i(0), kz + 1);
        const I after = select(next == 2, splat_i(0), next + 1);
        const F d_kz = pick_axis(L.dir, kz);
        swapped = d_kz < 0.f;
        kx = select(swapped, after, next);
        ky = select(swapped, next, after);
        shear[0] = pick_axis(L.dir, kx) / d_kz;
        shear[1] = pick_axis(L.dir, ky) / d_kz;
        shear[2] = splat(1.f) / d_kz;
        org[0] = pick_axis(L.org, kx);
        org[1] = pick_axis(L.org, ky);
        org[2] = pick_axis(L.org, kz);
    }
};
