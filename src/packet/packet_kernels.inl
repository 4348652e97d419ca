// SIMD packets (Wald's ray packets): tree and brute-force kernels that trace kLanes rays at once, one
// ray per lane (`Lanes`), included inside an instruction-set namespace after simd/lanes.inl (see
// accel/kernels_<isa>.cpp). A SIMD packet is not the renderer's P x P packet of pixels (schedule.hpp):
// that one arrives here as a batch, a span of rays, which the kernels cut into SIMD packets. The
// tree kernels are templates over a tree's traits (kernel/stack_traversal.hpp), like the single-ray
// kernels: a kd-tree node is a BIH node whose two planes coincide, and the traits say where a node's
// planes are, whether a ray can pass between them, and what a leaf's entries are.
//
// Exactness. A lane computes what the single-ray kernels compute for its ray: the same conservative
// plane tests with the same margin (kernel/traversal.hpp) and the watertight triangle test with the
// same operations in the same order (triangle.hpp), so its hit is the brute-force hit bit for bit. A
// SIMD packet visits a node when any of its active lanes would; lanes that would not are masked off,
// and a lane that tests a triangle its own ray would never have reached only adds a candidate that
// brute force tests too. So neither divergence nor the visiting order can change an answer.
//
// Large batches (the renderer's P x P packet, P >= 8) first run an entry-point search: the whole
// batch is bounded by interval arithmetic (a box of origins and a box of inverse directions, when all
// rays share their direction signs) and descends from the root while every ray in it needs only one
// child, culling the other subtrees for the whole batch at once (Reshetov, Soupikov, Hurley,
// "Multi-Level Ray Tracing Algorithm", SIGGRAPH 2005). Each SIMD packet of the batch starts there.
//
// No include guard: included once per instruction set.

#include "simd/ray_lanes.inl"

// One SIMD packet: kLanes rays as a structure of arrays, what the traversal and the watertight test
// need per lane.
struct Lanes {
    F org[3], inv[3];
    I neg[3];       // the direction's sign bit per axis: the near child is the right one
    F tnear, tfar, margin;
    F axis_margin[3];  // each axis' planes' (kernel/traversal.hpp, axis_margins)
    F sx, sy, sz;   // the watertight test's shear (WatertightRay)
    I perm;         // its axis permutation: 2 * kz + (kx and ky swapped)
    // The same permutation as lane masks, for SIMD packets whose lanes differ: role r (0: kx, 1: ky,
    // 2: kz) is the x axis where is_x[r], the y axis where is_y[r], z elsewhere; role_org[r] is the
    // origin's coordinate on that axis.
    I is_x[3], is_y[3];
    F role_org[3];
    I valid;        // lanes holding a valid ray
    int count = 0;  // rays loaded (the rest of the lanes are invalid)
    int shared = -1;  // the permutation all valid lanes share, or -1
};

inline F pick(I is0, I is1, F x, F y, F z) { return select(is0, x, select(is1, y, z)); }

// Loads n <= kLanes rays with every per-ray constant of the single-ray kernels (TraversalRay and
// WatertightRay) made lane by lane (simd/ray_lanes.inl), so lanes carry the same bits.
inline Lanes load_lanes(const Ray* rays, int n, const Box3& scene_box) {
    const RayLanes R = load_ray_lanes(rays, static_cast<std::size_t>(n), scene_box);
    const WatertightLanes W(R);
    Lanes L;
    L.count = n;
    for (int a = 0; a < 3; ++a) {
        L.org[a] = R.org[a];
        L.inv[a] = R.inv[a];
        L.neg[a] = R.negative[a];
        L.axis_margin[a] = R.axis_margin[a];
    }
    L.tnear = R.tnear;
    L.tfar = R.tfar;
    L.margin = R.margin;
    L.valid = R.valid;
    L.sx = W.shear[0];
    L.sy = W.shear[1];
    L.sz = W.shear[2];
    L.perm = W.kz + W.kz + (W.swapped & splat_i(1));
    const I role[3] = {W.kx, W.ky, W.kz};
    for (int r = 0; r < 3; ++r) {
        L.is_x[r] = role[r] == 0;
        L.is_y[r] = role[r] == 1;
        L.role_org[r] = W.org[r];
    }
    const unsigned valid_bits = bits(L.valid);
    if (valid_bits) {
        const int p = L.perm[__builtin_ctz(valid_bits)];
        L.shared = any(L.valid & (L.perm != p)) ? -1 : p;
    }
    return L;
}

// The lanes' intervals clipped to `box` and widened by the margins, as TraversalRay::clip does.
inline I clip_lanes(const Lanes& L, const Box3& box, F& tmin, F& tmax) {
    tmin = L.tnear - L.margin;
    tmax = L.tfar + L.margin;
    for (int a = 0; a < 3; ++a) {
        const F t0 = (splat(box.lo[a]) - L.org[a]) * L.inv[a];
        const F t1 = (splat(box.hi[a]) - L.org[a]) * L.inv[a];
        const F enter = select(L.neg[a], t1, t0), leave = select(L.neg[a], t0, t1);
        tmin = max_keep(tmin, enter - L.axis_margin[a]);
        tmax = min_keep(tmax, leave + L.axis_margin[a]);
    }
    return L.valid & (tmin <= tmax);
}

// The watertight test (triangle.hpp) of one triangle against the lanes of `mask`. When they share one
// axis permutation (`perm` >= 0; the common case for coherent rays) the vertex coordinates are
// broadcast; otherwise (`perm` < 0) each lane picks its own with masks, so a SIMD packet whose lanes
// point different ways still needs one pass. Returns the lanes whose ray meets the triangle, with t,
// u, v.
inline I watertight_lanes(const Lanes& L, int perm, const Triangle& tri, I mask, F& t, F& u, F& v) {
    int axis[3] = {0, 0, 0};
    if (perm >= 0) {
        axis[2] = perm / 2;
        axis[0] = axis[2] == 2 ? 0 : axis[2] + 1;
        axis[1] = axis[0] == 2 ? 0 : axis[0] + 1;
        if (perm & 1) std::swap(axis[0], axis[1]);
    }
    auto coord = [&](const Vec3& p, int role) {
        if (perm >= 0) return splat(p[static_cast<std::size_t>(axis[role])]);
        return pick(L.is_x[role], L.is_y[role], splat(p.x), splat(p.y), splat(p.z));
    };
    return watertight_in_lanes([&](int k, int role) { return coord(k == 0 ? tri.v0 : k == 1 ? tri.v1 : tri.v2, role); },
                               L.role_org[0], L.role_org[1], L.role_org[2], L.sx, L.sy, L.sz, mask, t, u, v);
}

// The permutation the lanes of `mask` share, or -1 when they differ.
inline int shared_perm(const Lanes& L, I mask) {
    if (L.shared >= 0) return L.shared;
    const unsigned b = bits(mask);
    if (!b) return -1;
    const int p = L.perm[__builtin_ctz(b)];
    return any(mask & (L.perm != p)) ? -1 : p;
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
        F t, u, v;
        const I hit = watertight_lanes(L, shared_perm(L, mask), tri, mask, t, u, v);
        const I accept = hit & (t >= L.tnear) & (t <= best_t);
        const I better = accept & ((t < best_t) | (I)(splat_u(prim) < best_prim));
        best_t = select(better, t, best_t);
        best_u = select(better, u, best_u);
        best_v = select(better, v, best_v);
        best_prim = select(better, splat_u(prim), best_prim);
    }

    void store(const Lanes& L, Hit* out) const {
        for (int i = 0; i < L.count; ++i)
            out[i] = best_prim[i] == kNoHit ? Hit{} : Hit{best_t[i], best_prim[i], best_u[i], best_v[i]};
    }

    // Lane i's query as a single ray's, run by `traverse`, and its answer taken back.
    template <class Traverse>
    void single(int i, const TraversalRay& r, Traverse&& traverse) {
        ClosestHit q(r);
        q.best = Hit{best_t[i], best_prim[i], best_u[i], best_v[i]};
        traverse(q);
        best_t[i] = q.best.t, best_prim[i] = q.best.prim, best_u[i] = q.best.u, best_v[i] = q.best.v;
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
        mask &= ~occluded;
        F t, u, v;
        const I hit = watertight_lanes(L, shared_perm(L, mask), tri, mask, t, u, v);
        occluded |= hit & (t >= L.tnear) & (t <= L.tfar);
    }

    void store(const Lanes& L, std::uint8_t* out) const {
        for (int i = 0; i < L.count; ++i) out[i] = occluded[i] ? 1 : 0;
    }

    template <class Traverse>
    void single(int i, const TraversalRay& r, Traverse&& traverse) {
        AnyHit q(r);
        if (traverse(q)) occluded[i] = -1;
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
    // Runs fn(counters) with the single-ray kernels' counters adding to the same sum.
    template <class Fn>
    auto single(Fn&& fn) const {
        if (sum) {
            WorkCounters c{*sum};
            return fn(c);
        }
        NoCounters c;
        return fn(c);
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

// The children's lane intervals at a plane of axis `a` crossed at t (per lane): the near child ends
// at t + m, the far one starts at t - m, m that axis' margin; left/right by each lane's direction
// sign. Returns the active lanes of each side.
inline void split_lanes(const Lanes& L, int a, F t_left_ends, F t_right_starts, F tmin, F tmax, I active, F& lmin,
                        F& lmax, F& rmin, F& rmax, I& left, I& right) {
    // Positive direction: left is near (ends at t_left_ends), right is far (starts at t_right_starts).
    // Negative direction: right is near and ends at t_right_starts, left is far and starts at t_left_ends.
    const I neg = L.neg[a];
    const F near_end = select(neg, t_right_starts, t_left_ends), far_start = select(neg, t_left_ends, t_right_starts);
    const F m = L.axis_margin[a];
    const I near_ok = ~(tmin > near_end + m), far_ok = ~(far_start - m > tmax);
    const F near_max = min_keep(tmax, near_end + m), far_min = max_keep(tmin, far_start - m);
    left = active & select(neg, far_ok, near_ok);
    right = active & select(neg, near_ok, far_ok);
    lmin = select(neg, far_min, tmin);
    lmax = select(neg, tmax, near_max);
    rmin = select(neg, tmin, far_min);
    rmax = select(neg, near_max, tmax);
}

// The last lane left in a subtree goes on as a single ray: lane `i` (ray `r`) through the subtree of
// node `index` with its interval [tmin, tmax] there, by the branched single-ray kernel, which visits
// what the lane would and tests triangles the same way, at a scalar step's price.
template <class Traits, class Query>
[[gnu::noinline]] void trace_single_lane(const TreeView<Traits>& tree, const TraversalRay& r, int i, Query& q,
                                         std::uint32_t index, float tmin, float tmax, LaneCounters c) {
    q.single(i, r, [&](auto& single_query) {
        return c.single([&](auto& counters) {
            auto mem = tree.memory();
            return traverse_branched_from<Traits>(mem, r, single_query, counters, index, tmin, tmax);
        });
    });
}

// Lanes whose directions point into opposite half-spaces on every axis: no view frustum or set of
// rays toward one light does that, random rays almost always do.
inline bool incoherent(const Lanes& L) {
    for (int a = 0; a < 3; ++a)
        if (!any(L.valid & L.neg[a]) || !any(L.valid & ~L.neg[a])) return false;
    return true;
}

// One SIMD packet through a tree from `start` (a node whose cell is `start_box`). Trees differ only in
// what their traits say: their inner nodes' planes (one, or two clip planes with a gap) and their
// leaves (indices into the scene's triangles, or ranges of the structure's reordered ones).
//
// `kHandOver`: whether a lane left alone in a subtree goes on as a single ray (trace_single_lane).
// Worth it for incoherent lanes, which soon spread over the tree: a scalar step is cheaper than a
// SIMD packet's step for one lane. Coherent SIMD packets are traced without it: they seldom leave a
// lane alone for long, and with the call in its loop the kernel ran coherent frames 10 to 20% slower.
template <bool kHandOver, class Traits, class Query>
inline void trace_lanes(const TreeView<Traits>& tree, const Lanes& L, const Ray* rays, Query& q, std::uint32_t start,
                        const Box3& start_box, LaneCounters c) {
    F tmin, tmax;
    I active = clip_lanes(L, start_box, tmin, tmax);
    if (!any(active)) return;
    // At most two entries per level (see below), plus one.
    constexpr int kStack = 2 * Traits::kMaxDepth + 2;
    LaneEntry stack[kStack];
    int sp = 0;
    std::uint32_t index = start;
    [[maybe_unused]] std::optional<TraversalRay> single_rays[kHandOver ? kLanes : 1];  // made on first use
    for (;;) {
        auto n = tree.nodes[index];
        bool at_leaf = true;
        while (!n.is_leaf()) {
            if constexpr (kHandOver) {
                if (const unsigned b = bits(active); (b & (b - 1)) == 0) {  // one lane left
                    const int i = __builtin_ctz(b);
                    if (!single_rays[i]) single_rays[i].emplace(rays[i], tree.bounds);
                    trace_single_lane(tree, *single_rays[i], i, q, index, tmin[i], tmax[i], c);
                    at_leaf = false;
                    break;
                }
            }
            c.node(active);
            const int a = n.axis();
            F lmin, lmax, rmin, rmax;
            I left, right;
            const F t_left = (splat(Traits::plane(n, 0)) - L.org[a]) * L.inv[a];
            F t_right = t_left;
            if constexpr (Traits::kGaps) t_right = (splat(Traits::plane(n, 1)) - L.org[a]) * L.inv[a];
            split_lanes(L, a, t_left, t_right, tmin, tmax, active, lmin, lmax, rmin, rmax, left, right);
            const unsigned left_bits = bits(left), right_bits = bits(right);
            const bool go_left = left_bits != 0, go_right = right_bits != 0;
            if (go_left && go_right) {
                // The majority's near child first. For a closest hit, lanes for which it is the far
                // child visit it after the other one, from an entry of their own below it: every
                // lane meets the cells in its own front-to-back order, as its single ray would, and
                // stops as early. (Any hit gains nothing from the order and would pay the extra visits.)
                const bool right_near = right_first(L.neg[a], active);
                I late = splat_i(0);
                if constexpr (!Query::kAnyHit) late = right_near ? right & ~L.neg[a] : left & L.neg[a];
                const std::uint32_t first = n.children() + (right_near ? 1u : 0u);
                const F first_min = right_near ? rmin : lmin, first_max = right_near ? rmax : lmax;
                if (any(late)) stack[sp++] = {first, first_min, first_max, late};
                if (right_near) stack[sp++] = {n.children(), lmin, lmax, left};
                else stack[sp++] = {n.children() + 1, rmin, rmax, right};
                index = first, tmin = first_min, tmax = first_max;
                active = (right_near ? right : left) & ~late;
                if (!any(active)) {
                    at_leaf = false;  // only late lanes need the near child: take the far one first
                    break;
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
            const auto mem = tree.memory();
            c.leaf(active);
            const std::uint32_t end = n.first() + n.count();
            for (std::uint32_t k = n.first(); k < end; ++k) {
                c.triangle(active);
                const LeafEntry e = Traits::leaf_entry(mem, k);
                q.test(L, e.triangle, e.prim, active);
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

// The incoherent instantiation out of line, so that the coherent one's caller is compiled as if it
// were the only one.
template <class Traits, class Query>
[[gnu::noinline]] void trace_incoherent_lanes(const TreeView<Traits>& tree, const Lanes& L, const Ray* rays, Query& q,
                                              std::uint32_t start, const Box3& start_box, LaneCounters c) {
    trace_lanes<true>(tree, L, rays, q, start, start_box, c);
}

inline float min_of(F x) {
    float m = x[0];
    for (int i = 1; i < kLanes; ++i) m = std::min(m, x[i]);
    return m;
}
inline float max_of(F x) {
    float m = x[0];
    for (int i = 1; i < kLanes; ++i) m = std::max(m, x[i]);
    return m;
}

// Entry-point search for a whole batch (see the top of this file). Returns the deepest node whose
// cell contains every ray's traversal, and sets `box` to that cell; the root when the batch is not
// coherent (invalid rays, mixed direction signs or zero direction components).
template <class Traits>
inline std::uint32_t entry_point(const TreeView<Traits>& tree, std::span<const Lanes> simd_packets, Box3& box) {
    box = tree.bounds;
    const F inf = splat(kInfinity);
    F olo[3] = {inf, inf, inf}, ohi[3] = {-inf, -inf, -inf}, ilo[3] = {inf, inf, inf}, ihi[3] = {-inf, -inf, -inf};
    F tmin_v = inf, tmax_v = -inf, margin_v[3] = {splat(0.f), splat(0.f), splat(0.f)};
    I negative[3] = {splat_i(0), splat_i(0), splat_i(0)}, positive[3] = {splat_i(0), splat_i(0), splat_i(0)};
    for (const Lanes& g : simd_packets) {
        I loaded = splat_i(0);
        for (int i = 0; i < g.count; ++i) loaded[i] = -1;
        if (any(loaded & ~g.valid)) return 0;
        F t0, t1;
        const I hit = clip_lanes(g, tree.bounds, t0, t1);
        for (int a = 0; a < 3; ++a) {
            if (any(g.valid & ~(abs_lanes(g.inv[a]) < kInfinity))) return 0;
            negative[a] |= g.valid & g.neg[a];
            positive[a] |= g.valid & ~g.neg[a];
            olo[a] = select(hit, min_keep(olo[a], g.org[a]), olo[a]);
            ohi[a] = select(hit, max_keep(ohi[a], g.org[a]), ohi[a]);
            ilo[a] = select(hit, min_keep(ilo[a], g.inv[a]), ilo[a]);
            ihi[a] = select(hit, max_keep(ihi[a], g.inv[a]), ihi[a]);
            margin_v[a] = select(hit, max_keep(margin_v[a], g.axis_margin[a]), margin_v[a]);
        }
        tmin_v = select(hit, min_keep(tmin_v, t0), tmin_v);
        tmax_v = select(hit, max_keep(tmax_v, t1), tmax_v);
    }
    std::uint32_t signs = 0;
    Vec3 o_lo, o_hi, i_lo, i_hi;
    for (int a = 0; a < 3; ++a) {
        if (any(negative[a]) && any(positive[a])) return 0;
        signs |= (any(negative[a]) ? 1u : 0u) << a;
        o_lo[a] = min_of(olo[a]), o_hi[a] = max_of(ohi[a]), i_lo[a] = min_of(ilo[a]), i_hi[a] = max_of(ihi[a]);
    }
    float tmin = min_of(tmin_v), tmax = max_of(tmax_v);
    const float margin[3] = {max_of(margin_v[0]), max_of(margin_v[1]), max_of(margin_v[2])};
    if (!(tmin <= tmax)) return 0;
    std::uint32_t index = 0;
    for (;;) {
        const auto& n = tree.nodes[index];
        if (n.is_leaf()) return index;
        const int a = n.axis();
        // Every lane's plane distance (s - o) * inv lies between the products of the interval ends:
        // rounding is monotonic in each operand.
        auto range = [&](float plane, float& lo, float& hi) {
            const float p[4] = {(plane - o_lo[a]) * i_lo[a], (plane - o_lo[a]) * i_hi[a], (plane - o_hi[a]) * i_lo[a],
                                (plane - o_hi[a]) * i_hi[a]};
            lo = std::min(std::min(p[0], p[1]), std::min(p[2], p[3]));
            hi = std::max(std::max(p[0], p[1]), std::max(p[2], p[3]));
        };
        float l_lo, l_hi, r_lo, r_hi;
        range(Traits::plane(n, 0), l_lo, l_hi);
        r_lo = l_lo, r_hi = l_hi;
        if constexpr (Traits::kGaps) range(Traits::plane(n, 1), r_lo, r_hi);
        const bool negative_dir = (signs >> a) & 1u;
        // Near child ends at its plane, far child starts at its plane (as in split_lanes).
        const float near_end_hi = negative_dir ? r_hi : l_hi, far_start_lo = negative_dir ? l_lo : r_lo;
        const bool near_needed = !(tmin > near_end_hi + margin[a]), far_needed = !(far_start_lo - margin[a] > tmax);
        if (near_needed == far_needed) return index;  // the batch splits here (or passes between planes)
        const bool left = negative_dir ? far_needed : near_needed;
        const float plane = Traits::plane(n, left ? 0u : 1u);
        if (left) box.hi[a] = std::min(box.hi[a], plane);
        else box.lo[a] = std::max(box.lo[a], plane);
        if (far_needed) tmin = std::max(tmin, far_start_lo - margin[a]);
        index = n.children() + (left ? 0u : 1u);
    }
}

// A batch through a tree, up to kSimdPackets SIMD packets at a time: loaded, an entry-point search
// when there is more than one, then each from the entry point.
constexpr std::size_t kSimdPackets = 64;

template <class Traits, class Query, class Out>
void trace_batch(const TreeView<Traits>& tree, std::span<const Ray> rays, std::span<Out> results,
                 TraversalCounters* counters) {
    Out* out = results.data();
    Lanes simd_packets[kSimdPackets];
    for (std::size_t begin = 0; begin < rays.size(); begin += kSimdPackets * kLanes) {
        const std::size_t end = std::min(rays.size(), begin + kSimdPackets * kLanes);
        std::size_t count = 0;
        // Made in place (a placement new of the returned value elides the copy): assigned, each
        // packet's 1.7 KB went through a temporary and a `rep movsq`, 2.3 % of the kd-tree's
        // closest-hit packets' samples on Sponza's camera rays (docs/INCOHERENT.md, "Twenty-first round").
        for (std::size_t i = begin; i < end; i += kLanes)
            ::new (static_cast<void*>(&simd_packets[count++]))
                Lanes(load_lanes(rays.data() + i, static_cast<int>(std::min<std::size_t>(kLanes, end - i)), tree.bounds));
        Box3 box = tree.bounds;
        const std::uint32_t start =
            count > 1 ? entry_point(tree, std::span<const Lanes>(simd_packets, count), box) : 0;
        for (std::size_t g = 0; g < count; ++g) {
            Query q(simd_packets[g]);
            const Ray* lane_rays = rays.data() + begin + g * kLanes;
            if (incoherent(simd_packets[g]))
                trace_incoherent_lanes(tree, simd_packets[g], lane_rays, q, start, box, LaneCounters{counters});
            else
                trace_lanes<false>(tree, simd_packets[g], lane_rays, q, start, box, LaneCounters{counters});
            q.store(simd_packets[g], out + begin + g * kLanes);
        }
    }
    if (counters) counters->rays += rays.size();
}

// Brute force, kLanes rays at a time: every triangle against every lane.
template <class Query, class Out>
void brute_batch(std::span<const Triangle> triangles, std::span<const Ray> rays, std::span<Out> results,
                 TraversalCounters* counters) {
    Out* out = results.data();
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

// This instruction set's table for brute force and the trees of traits `Traits...` (the registry's
// structures): instantiated here, inside the instruction set's target region and namespace.
template <class... Traits>
PacketTable<Traits...> make_packet_table() {
    return {kLanes,
            {&brute_batch<ClosestLanes, Hit>, &brute_batch<AnyLanes, std::uint8_t>},
            {TreePacketKernels<Traits>{&trace_batch<Traits, ClosestLanes, Hit>,
                                       &trace_batch<Traits, AnyLanes, std::uint8_t>}...}};
}
