// Packets of rays over the wide BVH (issue 18; after Wald, Benthin, Boulos 2008, "Getting Rid of
// Packets", whose BVH8 this is, and Embree's packet traversal, rtcIntersect8/16): eight (or
// sixteen, below) consecutive rays of a batch go down the tree together, one ray per SIMD lane. At
// a node each child's box is tested
// against the packet's rays at once, giving the rays that meet it; the packet goes on to the children
// some ray meets, each with those rays, the nearest first (by its rays' smallest entry; an any-hit
// query: the first met), the others waiting on one stack (closest hit: sorted, the nearest on top).
// So a coherent packet reads each node, pops the stack and takes each branch once for all its rays,
// where single rays (bvh_kernels.inl) do it once per ray; the arithmetic is the same. When few rays
// are left on a branch (kPacketSingleBelow) each goes on alone, with the single-ray kernel, from the
// node it reached.
//
// Exact: a ray's box test is meet_children's, lane for lane (the same operations in the same order,
// the plane it enters and leaves by chosen by its own direction's signs), and its leaves are tested
// by test_leaf with its own query. A ray therefore reaches a leaf only if it meets every box on the
// way, and then tests it as its own kernel would; a waiting branch is dropped for a ray only when
// the branch's smallest entry lies past the ray's cull distance (its best hit plus the margin), so
// past the ray's own entry, where its own kernel drops the branch too. The hit rule picks the same
// answer whatever the order, so the answers are brute force's.
//
// The packet is as wide as the namespace it is included in, after bvh_kernels.inl: the wide BVH's
// namespace of eight lanes, or (AVX-512) its instruction set's namespace of sixteen lanes, with
// the wide BVH's node, leaf and single-ray names brought in by using-declarations: sixteen rays
// share each node's fetch and loop, while a child's box and a leaf's triangles are still tested in
// eight lanes (Embree's rtcIntersect16 over its BVH8 likewise).
//
// No include guard: included once per namespace of lanes that traces packets.

// Rays per packet: one per lane.
inline constexpr int kPacketRays = kLanes;
static_assert(kPacketRays <= 32, "a packet's rays are the bits of an unsigned");

// The smallest of a packet's lanes: sixteen folded onto eight, then horizontal_min's eight.
template <class V>
inline float packet_min(V x) {
    if constexpr (sizeof(V) == 64) {
        const auto lo = __builtin_shufflevector(x, x, 0, 1, 2, 3, 4, 5, 6, 7);
        const auto hi = __builtin_shufflevector(x, x, 8, 9, 10, 11, 12, 13, 14, 15);
        return horizontal_min(hi < lo ? hi : lo);  // min_keep's choice
    } else {
        return horizontal_min(x);
    }
}

// A branch that this many rays of a packet or fewer go down is traced by each ray alone (the
// single-ray kernel), as Embree's hybrid traversal falls back to single rays when few lanes are left.
// Any hit: three, which traces a frame's shadow rays in 0.86 to 0.92 of the time one takes and AO
// rays in 0.96 to 0.97 (two as fast as three, four and six slower); closest hit: one, where two and
// three cost the camera rays 2 to 5 % (docs/INCOHERENT.md, "Twelfth round").
template <class Query>
inline constexpr int kPacketSingleBelow = Query::kAnyHit ? 3 : 1;

// The packet's rays that meet child `k` of `node` within [tnear - margin, cull], as lane bits, with
// each one's entry distance: meet_children's test of that child, in every ray's lane.
inline unsigned packet_meets(const BvhNode& node, int k, const RayLanes& p, F cull, F& entry) {
    F enter = p.tnear - p.margin, leave = cull;
    for (int a = 0; a < 3; ++a) {
        const F to_lo = (splat(node.lo[a][k]) - p.org[a]) * p.inv[a];
        const F to_hi = (splat(node.hi[a][k]) - p.org[a]) * p.inv[a];
        enter = max_keep(enter, select(p.negative[a], to_hi, to_lo) - p.axis_margin[a]);
        leave = min_keep(leave, select(p.negative[a], to_lo, to_hi) + p.axis_margin[a]);
    }
    entry = enter;
    return bits_le(entry, leave);
}

// A leaf's triangles against the packet's rays `rays`, one triangle at a time in every ray's lane (as
// Embree's packet kernels test a packet against a leaf's triangles), where test_leaf takes one ray at
// a time with the triangles in lanes: with more rays than triangles at the leaf, fewer passes. Each
// lane runs the watertight test in lanes (watertight_in_lanes, simd/ray_lanes.inl, as
// watertight_leaf) on its own ray's constants (`w`, the packet's WatertightLanes: its origin in its
// own axis order and its shear) and the triangle's coordinates picked in that order, so t, u and v
// carry the scalar test's bits; the hit rule then updates each ray's query, triangle after
// triangle, which picks the same hit as test_leaf's minimum over the lanes (the rule is a total
// order). The axis masks are made once per leaf, not per triangle as pick_axis (ray_lanes.inl)
// would. Returns the rays an any-hit query answered.
template <class Query, class Counters>
unsigned test_leaf_lanes(const BvhLeaf& leaf, std::uint32_t count, const WatertightLanes& w, const F& tnear,
                         unsigned rays, Query* q, F& cull, Counters& c) {
    for (unsigned m = rays; m; m &= m - 1) {
        c.leaf();
        for (std::uint32_t j = 0; j < count; ++j) c.triangle();
    }
    const I x0 = w.kx == 0, x1 = w.kx == 1, y0 = w.ky == 0, y1 = w.ky == 1, z0 = w.kz == 0, z1 = w.kz == 1;
    const I used = met_mask(rays);
    unsigned answered = 0;
    for (std::uint32_t j = 0; j < count; ++j) {
        // Vertex k's coordinates on each lane's kx, ky and kz axes (role 0, 1, 2).
        F vx[3], vy[3], vz[3];
        for (int k = 0; k < 3; ++k) {
            const F v0 = splat(leaf.v[k][0][j]), v1 = splat(leaf.v[k][1][j]), v2 = splat(leaf.v[k][2][j]);
            vx[k] = select(x0, v0, select(x1, v1, v2));
            vy[k] = select(y0, v0, select(y1, v1, v2));
            vz[k] = select(z0, v0, select(z1, v1, v2));
        }
        const auto coord = [&](int k, int role) { return role == 0 ? vx[k] : role == 1 ? vy[k] : vz[k]; };
        F t, u, v;
        const I hit = watertight_in_lanes(coord, w.org[0], w.org[1], w.org[2], w.shear[0], w.shear[1], w.shear[2], used,
                                          t, u, v) &
                      (t >= tnear);
        unsigned hits = bits(hit);
        if (!hits) continue;
        const std::uint32_t prim = leaf.prim[j];
        if constexpr (Query::kAnyHit) {
            for (; hits; hits &= hits - 1) {
                const int i = __builtin_ctz(hits);
                if (t[i] <= q[i].tfar) answered |= 1u << i;
            }
            if (answered == rays) break;
        } else {
            for (; hits; hits &= hits - 1) {
                const int i = __builtin_ctz(hits);
                if (closer(t[i], prim, q[i].best)) {
                    q[i].best = Hit{t[i], prim, u[i], v[i]};
                    cull[i] = q[i].cull_t();
                }
            }
        }
    }
    return answered;
}

// A branch waiting on the packet's stack: the node's word, its rays (lane bits) and their smallest entry.
struct PacketFrame {
    std::uint32_t word;
    unsigned rays;
    float entry;
};

// One packet through the tree: the batch's rays [0, kPacketRays) in `p`, `rays` the lanes of valid
// ones, each lane's query at its index of `q`. Returns the rays of `rays` not answered: an any-hit
// query's misses.
template <class Query, class Counters>
unsigned trace_packet(const BvhNode* nodes, const BvhLeaf* leaves, const RayLanes& p, Query* q,
                      unsigned rays, Counters& c) {
    constexpr bool kAny = Query::kAnyHit;
    F cull;
    for (int i = 0; i < kPacketRays; ++i) cull[i] = rays >> i & 1 ? q[i].cull_t() : -kInfinity;
    // The leaf test's set-up, made in lanes for the whole packet when its first ray reaches a leaf
    // (a camera packet that misses the object never does), and then each ray's LeafRay from its lane.
    std::optional<WatertightLanes> watertight;
    LeafRay leaf_rays[kPacketRays];
    unsigned leaf_made = 0;
    const auto leaf_ray = [&](int i) -> const LeafRay& {
        if (!(leaf_made >> i & 1)) {
            if (!watertight) watertight.emplace(p);
            leaf_rays[i] = leaf_ray_of_lane(*watertight, i);
            leaf_made |= 1u << i;
        }
        return leaf_rays[i];
    };
    unsigned active = rays;  // any hit: the rays not answered yet
    PacketFrame stack[kBvhStackSize + kBvhStackSlack];
    int size = 0;
    std::uint32_t word = 0;
    unsigned mask = rays;
    for (;;) {
        if (__builtin_popcount(mask) > kPacketSingleBelow<Query>) {
            if (BvhNode::is_leaf(word)) {
                const BvhLeaf& leaf = leaves[BvhNode::leaf_index(word)];
                const std::uint32_t count = BvhNode::leaf_count(word);
                if (static_cast<std::uint32_t>(__builtin_popcount(mask)) >= count) {
                    if (!watertight) watertight.emplace(p);
                    active &= ~test_leaf_lanes(leaf, count, *watertight, p.tnear, mask, q, cull, c);
                } else {
                    for (unsigned m = mask; m; m &= m - 1) {
                        const int i = __builtin_ctz(m);
                        if (test_leaf(leaf, count, leaf_ray(i), q[i], c)) active &= ~(1u << i);
                        if constexpr (!kAny) cull[i] = q[i].cull_t();
                    }
                }
            } else {
                const BvhNode& node = nodes[word];
                for (unsigned m = mask; m; m &= m - 1) c.node();
                unsigned children = node_children(node);
                unsigned met = 0, next = 0;
                unsigned child_rays[kBvhWidth];
                float key[kBvhWidth];
                float nearest = kInfinity;
                for (; children; children &= children - 1) {
                    const int k = __builtin_ctz(children);
                    F entry;
                    const unsigned m = packet_meets(node, k, p, cull, entry) & mask;
                    if (!m) continue;
                    child_rays[k] = m;
                    if constexpr (kAny) {
                        if (!met) next = static_cast<unsigned>(k);
                    } else {
                        key[k] = packet_min(select(met_mask(m), entry, splat(kInfinity)));
                        if (!met || key[k] < nearest) nearest = key[k], next = static_cast<unsigned>(k);
                    }
                    met |= 1u << k;
                }
                if (met) {
                    // Closest hit: the waiting children sorted, the nearest on top, so that the
                    // packet's hits come early and cull the farther ones (measured: 5 to 13 % less
                    // time on the camera rays of the bunny, Sponza and Sibenik than unsorted).
                    const int bottom = size;
                    for (unsigned rest = met & ~(1u << next); rest; rest &= rest - 1) {
                        const int k = __builtin_ctz(rest);
                        const PacketFrame f{node.child[k], child_rays[k], kAny ? 0.f : key[k]};
                        prefetch_child(nodes, leaves, f.word);
                        int at = size++;
                        if constexpr (!kAny) {
                            for (; at > bottom && stack[at - 1].entry < f.entry; --at) stack[at] = stack[at - 1];
                        }
                        stack[at] = f;
                    }
                    word = node.child[next];
                    mask = child_rays[next];
                    continue;
                }
            }
        } else {
            // Few rays left on this branch: each goes on with its own kernel from here.
            for (unsigned m = mask; m; m &= m - 1) {
                const int i = __builtin_ctz(m);
                const float org[3] = {p.org[0][i], p.org[1][i], p.org[2][i]};
                const float inv[3] = {p.inv[0][i], p.inv[1][i], p.inv[2][i]};
                const unsigned octant = (p.negative[0][i] & 1u) | (p.negative[1][i] & 1u) << 1 | (p.negative[2][i] & 1u) << 2;
                const float axis[3] = {p.axis_margin[0][i], p.axis_margin[1][i], p.axis_margin[2][i]};
                const BoxRay box(org, inv, octant, p.tnear[i], p.margin[i], axis);
                if (traverse_bvh_from(nodes, leaves, box, leaf_ray(i), word, q[i], c)) active &= ~(1u << i);
                if constexpr (!kAny) cull[i] = q[i].cull_t();
            }
        }
        // The next waiting branch with a ray that still needs it: not answered (any hit), or whose
        // cull distance is not before the branch's smallest entry (closest hit).
        for (;;) {
            if (size == 0) return active;
            const PacketFrame& f = stack[--size];
            mask = f.rays & active;
            if constexpr (!kAny) mask &= bits_le(splat(f.entry), cull);
            if (mask) {
                word = f.word;
                break;
            }
        }
    }
}

// The batch in packets of kPacketRays consecutive rays (the last may be short); invalid rays
// (ray.hpp) answer misses.
template <class Query, class Answer>
void packet_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<Answer> out, TraversalCounters* counters) {
    if (tree.nodes.empty()) return miss_all(rays, out, counters);
    with_counters(counters, rays.size(), [&](auto& count) {
        for (std::size_t first = 0; first < rays.size(); first += kPacketRays) {
            const std::size_t n = std::min<std::size_t>(kPacketRays, rays.size() - first);
            const RayLanes p = load_ray_lanes(&rays[first], n, tree.bounds);
            const unsigned valid = bits(p.valid);
            const auto make = [&]<std::size_t... L>(std::index_sequence<L...>) {
                return std::array<Query, kPacketRays>{Query(p.tnear[L], p.tfar[L], p.margin[L])...};
            };
            std::array<Query, kPacketRays> q = make(std::make_index_sequence<kPacketRays>());
            const unsigned missed =
                valid ? trace_packet(tree.nodes.data(), tree.leaves.data(), p, q.data(), valid, count)
                      : 0u;
            for (std::size_t i = 0; i < n; ++i) {
                if constexpr (Query::kAnyHit) out[first + i] = (valid & ~missed) >> i & 1;
                else out[first + i] = valid >> i & 1 ? q[i].result() : Hit{};
            }
        }
    });
}

inline void closest_packet_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<Hit> hits,
                                 TraversalCounters* counters) {
    packet_batch<ClosestHit>(tree, rays, hits, counters);
}

inline void any_packet_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                             TraversalCounters* counters) {
    packet_batch<AnyHit>(tree, rays, occluded, counters);
}

// The registry's table of the wide BVH's kernels with these packets (bvh_kernel_table).
inline const BvhKernels& bvh_kernels(const char* isa) {
    static const BvhKernels k = bvh_kernel_table(isa, &closest_packet_batch, &any_packet_batch, kPacketRays);
    return k;
}
