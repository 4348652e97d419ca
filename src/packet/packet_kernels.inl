// SIMD ray packets: kd-tree, BIH and brute-force kernels that trace kLanes rays at once, one ray per
// lane, included inside an instruction-set namespace after simd/lanes.inl (see packet_<isa>.cpp).
//
// Exactness. A lane computes what the single-ray kernels compute for its ray: the same conservative
// plane tests with the same margin (accel/traversal.hpp) and the watertight triangle test with the
// same operations in the same order (triangle.hpp), so its hit is the brute-force hit bit for bit. A
// packet visits a node when any of its active lanes would; lanes that would not are masked off, and
// a lane that tests a triangle its own ray would never have reached only adds a candidate that brute
// force tests too. So neither divergence nor the visiting order can change an answer.
//
// Large batches (a P x P packet of the renderer, P >= 8) first run an entry-point search: the whole
// batch is bounded by interval arithmetic (a box of origins and a box of inverse directions, when all
// rays share their direction signs) and descends from the root while every ray in it needs only one
// child, culling the other subtrees for the whole batch at once (Reshetov, Soupikov, Hurley,
// "Multi-Level Ray Tracing Algorithm", SIGGRAPH 2005). Each group of kLanes rays then starts there.
//
// No include guard: included once per instruction set.

// kLanes rays, structure of arrays: what the traversal and the watertight test need per lane.
struct Lanes {
    F org[3], inv[3];
    I neg[3];       // the direction's sign bit per axis: the near child is the right one
    F tnear, tfar, margin;
    F sx, sy, sz;   // the watertight test's shear (WatertightRay)
    I perm;         // its axis permutation: 2 * kz + (kx and ky swapped)
    I valid;        // lanes holding a valid ray
    int count = 0;  // rays loaded (the rest of the lanes are invalid)
};

inline F abs_lanes(F x) { return (F)((I)x & splat_i(0x7fffffff)); }
inline F max_lanes(F a, F b) { return select(a < b, b, a); }  // std::max's choice, lane by lane
inline F pick(I is0, I is1, F x, F y, F z) { return select(is0, x, select(is1, y, z)); }

// Loads n <= kLanes rays and computes, lane by lane, every per-ray constant of the single-ray kernels
// (TraversalRay and WatertightRay) with the same operations, so lanes carry the same bits.
inline Lanes load_lanes(const Ray* rays, int n, const Box3& scene_box) {
    Lanes L;
    L.count = n;
    F o[3], d[3], tnear = splat(0.f), tfar = splat(0.f);
    for (int a = 0; a < 3; ++a) o[a] = d[a] = splat(0.f);
    I loaded = splat_i(0);
    for (int i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) o[a][i] = rays[i].org[a], d[a][i] = rays[i].dir[a];
        tnear[i] = rays[i].tnear;
        tfar[i] = rays[i].tfar;
        loaded[i] = -1;
    }
    // is_valid (ray.hpp): finite origin and direction (x - x is 0 only for finite x), a direction
    // that is not zero, tnear <= tfar, no NaN bound.
    I finite = loaded;
    for (int a = 0; a < 3; ++a) finite &= ((o[a] - o[a]) == 0.f) & ((d[a] - d[a]) == 0.f);
    L.valid = finite & ~((d[0] == 0.f) & (d[1] == 0.f) & (d[2] == 0.f)) & ~(tnear > tfar) & (tnear == tnear) &
              (tfar == tfar);
    // Invalid lanes get a harmless ray, so that nothing below divides by zero or meets a NaN.
    for (int a = 0; a < 3; ++a) {
        o[a] = select(L.valid, o[a], splat(0.f));
        d[a] = select(L.valid, d[a], splat(1.f));
    }
    for (int a = 0; a < 3; ++a) {
        L.org[a] = o[a];
        L.inv[a] = splat(1.f) / d[a];
        L.neg[a] = (I)d[a] < 0;  // the sign bit, -0 included
    }
    L.tnear = tnear;
    L.tfar = tfar;
    F reach[3];
    for (int a = 0; a < 3; ++a)
        reach[a] = max_lanes(abs_lanes(splat(scene_box.lo[a]) - o[a]), abs_lanes(splat(scene_box.hi[a]) - o[a]));
    const F reach_length = sqrt_lanes(reach[0] * reach[0] + reach[1] * reach[1] + reach[2] * reach[2]);
    const F dir_length = sqrt_lanes(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    L.margin = splat(kMarginScale) * reach_length / dir_length;
    // WatertightRay: kz the largest |d| (ties to the lower axis), kx and ky the next ones, swapped
    // when d[kz] is negative.
    const F m0 = abs_lanes(d[0]), m1 = abs_lanes(d[1]), m2 = abs_lanes(d[2]);
    const I z0 = (m0 >= m1) & (m0 >= m2), z1 = ~(m0 >= m1) & (m1 >= m2);
    const F dz = pick(z0, z1, d[0], d[1], d[2]);
    const I swap = dz < 0.f;
    // kx = kz + 1 and ky = kz + 2 (mod 3), or the other way round when swapped.
    const F d_next = pick(z0, z1, d[1], d[2], d[0]), d_after = pick(z0, z1, d[2], d[0], d[1]);
    L.sx = select(swap, d_after, d_next) / dz;
    L.sy = select(swap, d_next, d_after) / dz;
    L.sz = splat(1.f) / dz;
    L.perm = select(z0, splat_i(0), select(z1, splat_i(2), splat_i(4))) + (swap & splat_i(1));
    return L;
}

// The lanes' intervals clipped to `box` and widened by the margin, as TraversalRay::clip does.
inline I clip_lanes(const Lanes& L, const Box3& box, F& tmin, F& tmax) {
    tmin = L.tnear - L.margin;
    tmax = L.tfar + L.margin;
    for (int a = 0; a < 3; ++a) {
        const F t0 = (splat(box.lo[a]) - L.org[a]) * L.inv[a];
        const F t1 = (splat(box.hi[a]) - L.org[a]) * L.inv[a];
        const F enter = select(L.neg[a], t1, t0), leave = select(L.neg[a], t0, t1);
        tmin = max_keep(tmin, enter - L.margin);
        tmax = min_keep(tmax, leave + L.margin);
    }
    return L.valid & (tmin <= tmax);
}

// The watertight test (triangle.hpp) of one triangle against the lanes of `mask`, which share the
// axis permutation `perm`. Returns the lanes whose ray meets the triangle, with t, u, v.
inline I watertight_lanes(const Lanes& L, int perm, const Triangle& tri, I mask, F& t, F& u, F& v) {
    const int kz = perm / 2;
    int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
    if (perm & 1) std::swap(kx, ky);
    const F ox = L.org[kx], oy = L.org[ky], oz = L.org[kz];
    const F a_kz = splat(tri.v0[kz]) - oz, b_kz = splat(tri.v1[kz]) - oz, c_kz = splat(tri.v2[kz]) - oz;
    const F ax = (splat(tri.v0[kx]) - ox) - L.sx * a_kz, ay = (splat(tri.v0[ky]) - oy) - L.sy * a_kz;
    const F bx = (splat(tri.v1[kx]) - ox) - L.sx * b_kz, by = (splat(tri.v1[ky]) - oy) - L.sy * b_kz;
    const F cx = (splat(tri.v2[kx]) - ox) - L.sx * c_kz, cy = (splat(tri.v2[ky]) - oy) - L.sy * c_kz;
    F eu = cx * by - cy * bx;
    F ev = ax * cy - ay * cx;
    F ew = bx * ay - by * ax;
    const I zero = mask & ((eu == 0.f) | (ev == 0.f) | (ew == 0.f));
    if (any(zero)) {
        for (int i = 0; i < kLanes; ++i) {
            if (zero[i] == 0) continue;
            eu[i] = static_cast<float>(double(cx[i]) * double(by[i]) - double(cy[i]) * double(bx[i]));
            ev[i] = static_cast<float>(double(ax[i]) * double(cy[i]) - double(ay[i]) * double(cx[i]));
            ew[i] = static_cast<float>(double(bx[i]) * double(ay[i]) - double(by[i]) * double(ax[i]));
        }
    }
    const I negative = (eu < 0.f) | (ev < 0.f) | (ew < 0.f);
    const I positive = (eu > 0.f) | (ev > 0.f) | (ew > 0.f);
    const F det = eu + ev + ew;
    const I hit = mask & ~(negative & positive) & (det != 0.f);
    const F az = L.sz * a_kz, bz = L.sz * b_kz, cz = L.sz * c_kz;
    const F big_t = eu * az + ev * bz + ew * cz;
    const F inv_det = splat(1.f) / det;
    t = big_t * inv_det;
    u = ev * inv_det;
    v = ew * inv_det;
    return hit;
}

// Runs `fn(perm, lanes)` for each axis permutation present among the lanes of `mask`.
template <class Fn>
inline void for_each_perm(const Lanes& L, I mask, Fn&& fn) {
    unsigned todo = bits(mask);
    while (todo) {
        const int p = L.perm[__builtin_ctz(todo)];
        const I same = mask & (L.perm == p);
        todo &= ~bits(same);
        fn(p, same);
    }
}

// Closest hit per lane under the hit rule (ray.hpp).
struct ClosestLanes {
    static constexpr bool kAnyHit = false;
    F best_t, best_u, best_v;
    U best_prim;

    explicit ClosestLanes(const Lanes& L) : best_t(L.tfar), best_u(splat(0.f)), best_v(splat(0.f)), best_prim(splat_u(kNoHit)) {}

    // Lanes whose stacked interval starting at `tmin` may still hold their answer.
    I alive(const Lanes& L, F tmin) const { return ~(tmin > best_t + L.margin); }
    I finished() const { return splat_i(0); }

    void test(const Lanes& L, const Triangle& tri, std::uint32_t prim, I mask) {
        for_each_perm(L, mask, [&](int p, I lanes) {
            F t, u, v;
            const I hit = watertight_lanes(L, p, tri, lanes, t, u, v);
            const I accept = hit & (t >= L.tnear) & (t <= best_t);
            const I better = accept & ((t < best_t) | (I)(splat_u(prim) < best_prim));
            best_t = select(better, t, best_t);
            best_u = select(better, u, best_u);
            best_v = select(better, v, best_v);
            best_prim = select(better, splat_u(prim), best_prim);
        });
    }

    void store(const Lanes& L, Hit* out) const {
        for (int i = 0; i < L.count; ++i)
            out[i] = best_prim[i] == kNoHit ? Hit{} : Hit{best_t[i], best_prim[i], best_u[i], best_v[i]};
    }
};

// Any hit per lane: a lane is finished at its first triangle with tnear <= t <= tfar.
struct AnyLanes {
    static constexpr bool kAnyHit = true;
    I occluded = splat_i(0);

    explicit AnyLanes(const Lanes&) {}

    I alive(const Lanes& L, F tmin) const { return ~occluded & ~(tmin > L.tfar + L.margin); }
    I finished() const { return occluded; }

    void test(const Lanes& L, const Triangle& tri, std::uint32_t, I mask) {
        for_each_perm(L, mask & ~occluded, [&](int p, I lanes) {
            F t, u, v;
            const I hit = watertight_lanes(L, p, tri, lanes, t, u, v);
            occluded |= hit & (t >= L.tnear) & (t <= L.tfar);
        });
    }

    void store(const Lanes& L, std::uint8_t* out) const {
        for (int i = 0; i < L.count; ++i) out[i] = occluded[i] ? 1 : 0;
    }
};

// Work counters: lane visits, so that the figures per ray compare with the single-ray kernels'.
struct LaneCounters {
    TraversalCounters* sum;
    void node(I active) const {
        if (sum) sum->nodes += static_cast<unsigned>(__builtin_popcount(bits(active)));
    }
    void leaf(I active) const {
        if (sum) sum->leaves += static_cast<unsigned>(__builtin_popcount(bits(active)));
    }
    void triangle(I active) const {
        if (sum) sum->triangles += static_cast<unsigned>(__builtin_popcount(bits(active)));
    }
};

struct LaneEntry {
    std::uint32_t node;
    F tmin, tmax;
    I active;
};

// Which of two children to visit first when lanes disagree about the near one: the majority's.
inline bool right_first(I neg, I active) {
    return 2 * __builtin_popcount(bits(neg & active)) > __builtin_popcount(bits(active));
}

// The children's lane intervals at a plane crossed at t (per lane): the near child ends at t + m,
// the far one starts at t - m; left/right by each lane's direction sign. Returns the active lanes of
// each side.
inline void split_lanes(const Lanes& L, int a, F t_left_ends, F t_right_starts, F tmin, F tmax, I active, F& lmin,
                        F& lmax, F& rmin, F& rmax, I& left, I& right) {
    // Positive direction: left is near (ends at t_left_ends), right is far (starts at t_right_starts).
    // Negative direction: right is near and ends at t_right_starts, left is far and starts at t_left_ends.
    const I neg = L.neg[a];
    const F near_end = select(neg, t_right_starts, t_left_ends), far_start = select(neg, t_left_ends, t_right_starts);
    const I near_ok = ~(tmin > near_end + L.margin), far_ok = ~(far_start - L.margin > tmax);
    const F near_max = min_keep(tmax, near_end + L.margin), far_min = max_keep(tmin, far_start - L.margin);
    left = active & select(neg, far_ok, near_ok);
    right = active & select(neg, near_ok, far_ok);
    lmin = select(neg, far_min, tmin);
    lmax = select(neg, tmax, near_max);
    rmin = select(neg, tmin, far_min);
    rmax = select(neg, near_max, tmax);
}

// One packet through a kd-tree or a BIH from `start` (a node whose cell is `start_box`). The two
// structures differ only in their inner nodes (one plane, or two clip planes) and their leaves
// (indices into the scene's triangles, or ranges of the BIH's reordered ones).
template <class Tree, class Query>
inline void trace_lanes(const Tree& tree, const Triangle* triangles, const Lanes& L, Query& q, std::uint32_t start,
                        const Box3& start_box, LaneCounters c) {
    F tmin, tmax;
    I active = clip_lanes(L, start_box, tmin, tmax);
    if (!any(active)) return;
    constexpr int kStack = 66;
    LaneEntry stack[kStack];
    int sp = 0;
    std::uint32_t index = start;
    for (;;) {
        auto n = tree.nodes[index];
        bool at_leaf = true;
        while (!n.is_leaf()) {
            c.node(active);
            const int a = n.axis();
            F lmin, lmax, rmin, rmax;
            I left, right;
            if constexpr (std::is_same_v<decltype(n), KdNode>) {
                const F t = (splat(n.split()) - L.org[a]) * L.inv[a];
                split_lanes(L, a, t, t, tmin, tmax, active, lmin, lmax, rmin, rmax, left, right);
            } else {
                const F t_left = (splat(n.clip(0)) - L.org[a]) * L.inv[a];
                const F t_right = (splat(n.clip(1)) - L.org[a]) * L.inv[a];
                split_lanes(L, a, t_left, t_right, tmin, tmax, active, lmin, lmax, rmin, rmax, left, right);
            }
            const bool go_left = any(left), go_right = any(right);
            if (go_left && go_right) {
                if (right_first(L.neg[a], active)) {
                    stack[sp++] = {n.children(), lmin, lmax, left};
                    index = n.children() + 1, tmin = rmin, tmax = rmax, active = right;
                } else {
                    stack[sp++] = {n.children() + 1, rmin, rmax, right};
                    index = n.children(), tmin = lmin, tmax = lmax, active = left;
                }
            } else if (go_left) {
                index = n.children(), tmin = lmin, tmax = lmax, active = left;
            } else if (go_right) {
                index = n.children() + 1, tmin = rmin, tmax = rmax, active = right;
            } else {
                at_leaf = false;  // every lane passes between a BIH node's two planes
                break;
            }
            n = tree.nodes[index];
        }
        if (at_leaf) {
            c.leaf(active);
            const std::uint32_t end = n.first() + n.count();
            for (std::uint32_t k = n.first(); k < end; ++k) {
                c.triangle(active);
                if constexpr (std::is_same_v<decltype(n), KdNode>) {
                    const std::uint32_t prim = tree.indices[k];
                    q.test(L, triangles[prim], prim, active);
                } else {
                    q.test(L, tree.triangles[k], tree.prims[k], active);
                }
                if constexpr (Query::kAnyHit) {
                    active &= ~q.finished();
                    if (!any(active)) break;
                }
            }
        }
        for (;;) {
            if (sp == 0) return;
            const LaneEntry& e = stack[--sp];
            active = e.active & q.alive(L, e.tmin);
            if (any(active)) {
                index = e.node;
                tmin = e.tmin;
                tmax = e.tmax;
                break;
            }
        }
    }
}

// Entry-point search for a whole batch (see the top of this file). Returns the deepest node whose
// cell contains every ray's traversal, and sets `box` to that cell; the root when the batch is not
// coherent (invalid rays, mixed direction signs or zero direction components).
template <class Tree>
inline std::uint32_t entry_point(const Tree& tree, std::span<const Ray> rays, Box3& box) {
    box = tree.bounds;
    Vec3 olo(kInfinity), ohi(-kInfinity), ilo(kInfinity), ihi(-kInfinity);
    float tmin = kInfinity, tmax = -kInfinity, margin = 0.f;
    bool first = true;
    std::uint32_t signs = 0;
    for (const Ray& ray : rays) {
        if (!is_valid(ray)) return 0;
        const TraversalRay r(ray, tree.bounds);
        std::uint32_t s = 0;
        for (int a = 0; a < 3; ++a) {
            if (!(std::fabs(r.inv_dir[a]) < kInfinity) || r.dir[a] == 0.f) return 0;
            s |= r.dir_neg[a] << a;
        }
        if (!first && s != signs) return 0;
        signs = s;
        first = false;
        float t0, t1;
        if (!r.clip(tree.bounds, t0, t1)) continue;
        olo = min(olo, r.org);
        ohi = max(ohi, r.org);
        ilo = min(ilo, Vec3{r.inv_dir[0], r.inv_dir[1], r.inv_dir[2]});
        ihi = max(ihi, Vec3{r.inv_dir[0], r.inv_dir[1], r.inv_dir[2]});
        tmin = std::min(tmin, t0);
        tmax = std::max(tmax, t1);
        margin = std::max(margin, r.margin);
    }
    if (!(tmin <= tmax)) return 0;
    std::uint32_t index = 0;
    for (;;) {
        const auto& n = tree.nodes[index];
        if (n.is_leaf()) return index;
        const int a = n.axis();
        // Every lane's plane distance (s - o) * inv lies between the products of the interval ends:
        // rounding is monotonic in each operand.
        auto range = [&](float plane, float& lo, float& hi) {
            const float p[4] = {(plane - olo[a]) * ilo[a], (plane - olo[a]) * ihi[a], (plane - ohi[a]) * ilo[a],
                                (plane - ohi[a]) * ihi[a]};
            lo = std::min(std::min(p[0], p[1]), std::min(p[2], p[3]));
            hi = std::max(std::max(p[0], p[1]), std::max(p[2], p[3]));
        };
        float l_lo, l_hi, r_lo, r_hi;
        if constexpr (std::is_same_v<std::decay_t<decltype(n)>, KdNode>) {
            range(n.split(), l_lo, l_hi);
            r_lo = l_lo, r_hi = l_hi;
        } else {
            range(n.clip(0), l_lo, l_hi);
            range(n.clip(1), r_lo, r_hi);
        }
        const bool negative = (signs >> a) & 1u;
        // Near child ends at its plane, far child starts at its plane (as in split_lanes).
        const float near_end_hi = negative ? r_hi : l_hi, far_start_lo = negative ? l_lo : r_lo;
        const bool near_needed = !(tmin > near_end_hi + margin), far_needed = !(far_start_lo - margin > tmax);
        if (near_needed == far_needed) return index;  // the batch splits here (or passes between planes)
        const bool left = negative ? far_needed : near_needed;
        float plane;
        if constexpr (std::is_same_v<std::decay_t<decltype(n)>, KdNode>) plane = n.split();
        else plane = left ? n.clip(0) : n.clip(1);
        if (left) box.hi[a] = std::min(box.hi[a], plane);
        else box.lo[a] = std::max(box.lo[a], plane);
        if (far_needed) tmin = std::max(tmin, far_start_lo - margin);
        index = n.children() + (left ? 0u : 1u);
    }
}

// A batch through a tree: entry-point search when it is larger than one packet, then kLanes rays at
// a time from the entry point.
template <class Tree, class Query, class Out>
inline void trace_batch(const Tree& tree, const Triangle* triangles, std::span<const Ray> rays, Out* out,
                        TraversalCounters* counters) {
    Box3 box = tree.bounds;
    const std::uint32_t start = rays.size() > static_cast<std::size_t>(kLanes) ? entry_point(tree, rays, box) : 0;
    for (std::size_t i = 0; i < rays.size(); i += kLanes) {
        const int n = static_cast<int>(std::min<std::size_t>(kLanes, rays.size() - i));
        const Lanes L = load_lanes(rays.data() + i, n, tree.bounds);
        Query q(L);
        trace_lanes(tree, triangles, L, q, start, box, LaneCounters{counters});
        q.store(L, out + i);
    }
    if (counters) counters->rays += rays.size();
}

// Brute force, kLanes rays at a time: every triangle against every lane.
template <class Query, class Out>
inline void brute_batch(std::span<const Triangle> triangles, std::span<const Ray> rays, Out* out,
                        TraversalCounters* counters) {
    Box3 bounds;
    for (const Triangle& t : triangles) bounds.extend(t.bounds());
    for (std::size_t i = 0; i < rays.size(); i += kLanes) {
        const int n = static_cast<int>(std::min<std::size_t>(kLanes, rays.size() - i));
        const Lanes L = load_lanes(rays.data() + i, n, bounds);
        Query q(L);
        I active = L.valid;
        for (std::uint32_t p = 0; p < triangles.size() && any(active); ++p) {
            q.test(L, triangles[p], p, active);
            if constexpr (Query::kAnyHit) active &= ~q.finished();
        }
        q.store(L, out + i);
        if (counters) counters->triangles += triangles.size() * static_cast<std::size_t>(n);
    }
    if (counters) counters->rays += rays.size();
}

inline const PacketKernels& kernels() {
    static const PacketKernels k{
        kLanes,
        [](const KdTree& t, const Triangle* tris, std::span<const Ray> r, std::span<Hit> h, TraversalCounters* c) {
            trace_batch<KdTree, ClosestLanes>(t, tris, r, h.data(), c);
        },
        [](const KdTree& t, const Triangle* tris, std::span<const Ray> r, std::span<std::uint8_t> o,
           TraversalCounters* c) { trace_batch<KdTree, AnyLanes>(t, tris, r, o.data(), c); },
        [](const BihTree& t, std::span<const Ray> r, std::span<Hit> h, TraversalCounters* c) {
            trace_batch<BihTree, ClosestLanes>(t, nullptr, r, h.data(), c);
        },
        [](const BihTree& t, std::span<const Ray> r, std::span<std::uint8_t> o, TraversalCounters* c) {
            trace_batch<BihTree, AnyLanes>(t, nullptr, r, o.data(), c);
        },
        [](std::span<const Triangle> tris, std::span<const Ray> r, std::span<Hit> h, TraversalCounters* c) {
            brute_batch<ClosestLanes>(tris, r, h.data(), c);
        },
        [](std::span<const Triangle> tris, std::span<const Ray> r, std::span<std::uint8_t> o, TraversalCounters* c) {
            brute_batch<AnyLanes>(tris, r, o.data(), c);
        },
    };
    return k;
}
