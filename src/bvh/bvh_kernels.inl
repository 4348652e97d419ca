// The wide BVH's single-ray kernels, included by each instruction set's translation unit
// (accel/kernels_<isa>.cpp) inside its target region, in a namespace of their own after
// simd/lanes.inl with kLanes = 8: one lane per child of a node and per triangle of a leaf.
//
// A node: the ray's slab distances to the eight child boxes, widened by the ray's margins
// (kernel/traversal.hpp) exactly as the scalar clip() widens the scene box, so that a box is missed
// only when the ray passes it by more than its margin; the children met are visited nearest first
// (an any-hit query: the first met), the others pushed with their entry distance and skipped when
// popped past the query's cull distance.
// A leaf: the watertight test (triangle.hpp) of its triangles, lane by lane in the scalar test's
// operations and order, so each lane's t, u and v are the scalar test's bits; the hit rule then picks
// among the lanes. Hence the kernels return exactly the hits of brute force (the lanes leave t's
// finiteness to the queries' bounds, which are finite: kernel/traversal.hpp).
//
// No include guard: every instruction set's unit includes it once, in a namespace of its own.

static_assert(kLanes == kBvhWidth, "one lane per child and per triangle");

#include "simd/ray_lanes.inl"

// Eight floats or words read in place, at any alignment: one vector load (a memcpy into the vector
// type compiles, under GCC 12, to a load, a store to the stack and a load back).
typedef float FRow __attribute__((vector_size(4 * kLanes), aligned(4), may_alias));
typedef std::uint32_t URow __attribute__((vector_size(4 * kLanes), aligned(4), may_alias));
inline F load(const float* p) { return *reinterpret_cast<const FRow*>(p); }
inline U load_u(const std::uint32_t* p) { return *reinterpret_cast<const URow*>(p); }

// The ray as the box tests of every node see it: its origin, reciprocal direction and each axis'
// margin (axis_margins) in all lanes, its tnear less its margin, and for each axis the offset (in
// floats, from the node's lo[0]) of the planes it enters and leaves a box by, chosen once by the
// direction's sign.
struct BoxRay {
    F org[3], inv[3], margin[3];
    float tmin;
    int enter[3], leave[3];

    explicit BoxRay(const TraversalRay& r)
        : BoxRay(r.org, r.inv_dir, r.octant(), r.tnear, r.margin, r.axis_margin) {}
    // From the origin, reciprocal direction and axis margins (anything indexed by axis: a stream's
    // stored ray, bvh_stream.inl, keeps them as floats), the direction's sign bits, tnear and the
    // margin in t.
    template <class Origin, class Inverse, class Margins>
    BoxRay(const Origin& o, const Inverse& i, unsigned negative, float near, float m, const Margins& axis)
        : tmin(near - m) {
        for (int a = 0; a < 3; ++a) {
            org[a] = splat(o[a]);
            inv[a] = splat(i[a]);
            margin[a] = splat(axis[a]);
            const int lo = a * kBvhWidth, hi = (3 + a) * kBvhWidth;
            enter[a] = negative >> a & 1 ? hi : lo;
            leave[a] = negative >> a & 1 ? lo : hi;
        }
    }
};

// A node's children met by the ray within [tnear - margin, cull], as a lane mask, with each one's
// entry distance: the scalar clip()'s operations, each plane distance widened by its axis' margin
// (a NaN one, of a ray lying in the plane, skipped by the NaN-keeping max and min).
inline I meet_children_lanes(const BvhNode& node, const BoxRay& r, float cull, F& entry) {
    static_assert(offsetof(BvhNode, hi) == 3 * kBvhWidth * sizeof(float), "hi follows lo");
    const float* planes = &node.lo[0][0];
    F enter = splat(r.tmin), leave = splat(cull);
    for (int a = 0; a < 3; ++a) {
        enter = max_keep(enter, (load(planes + r.enter[a]) - r.org[a]) * r.inv[a] - r.margin[a]);
        leave = min_keep(leave, (load(planes + r.leave[a]) - r.org[a]) * r.inv[a] + r.margin[a]);
    }
    entry = enter;
    return entry <= leave;
}
// The same as a bit mask.
inline unsigned meet_children(const BvhNode& node, const BoxRay& r, float cull, F& entry) {
    return bits(meet_children_lanes(node, r, cull, entry));
}

// The watertight test's per-ray constants (triangle.hpp's WatertightRay) in all lanes, made once per
// ray rather than once per leaf, with the offsets (in floats, within one vertex's rows) of the rows
// that the test reads as its x, y and z.
struct LeafRay {
    F ox, oy, oz, sx, sy, sz;
    int kx, ky, kz;

    LeafRay() = default;  // filled in later (bvh_packet.inl makes a packet's rays' on demand)
    explicit LeafRay(const WatertightRay& r)
        : ox(splat(r.org[r.kx])), oy(splat(r.org[r.ky])), oz(splat(r.org[r.kz])), sx(splat(r.sx)), sy(splat(r.sy)),
          sz(splat(r.sz)), kx(r.kx * kBvhWidth), ky(r.ky * kBvhWidth), kz(r.kz * kBvhWidth) {}
    // The same from a stream's stored ray: the origin in the test's axis order (o), the shear (s)
    // and the axes.
    LeafRay(const float* o, const float* s, int x, int y, int z)
        : ox(splat(o[0])), oy(splat(o[1])), oz(splat(o[2])), sx(splat(s[0])), sy(splat(s[1])), sz(splat(s[2])),
          kx(x * kBvhWidth), ky(y * kBvhWidth), kz(z * kBvhWidth) {}
};

// A ray as the node and leaf tests read it, in one cache line: the box test's origin, reciprocal
// direction, tnear, margin and axis margins, and the watertight test's shear and axes (its origin
// is the box test's, read in its axis order).
struct alignas(64) PreparedRay {
    float org[3], tnear;
    float inv[3], margin;
    float axis_margin[3];  // kernel/traversal.hpp's axis_margins
    float shear[3];        // sx, sy, sz
    std::uint32_t code;    // bits 0-2: the direction's sign bits (x, y, z); 3-4: kx; 5-6: ky; 7-8: kz
    std::uint32_t unused;

    unsigned octant() const { return code & 7u; }
    BoxRay box() const { return BoxRay(org, inv, code, tnear, margin, axis_margin); }
    LeafRay leaf() const {
        const int x = static_cast<int>(code >> 3 & 3u), y = static_cast<int>(code >> 5 & 3u), z = static_cast<int>(code >> 7 & 3u);
        const float o[3] = {org[x], org[y], org[z]};
        return LeafRay(o, shear, x, y, z);
    }
};
static_assert(sizeof(PreparedRay) == 64, "a prepared ray is one cache line");
static_assert(offsetof(PreparedRay, axis_margin) == 32, "prepare_rays writes a prepared ray as two rows of eight");

// The node's child slots that hold a child (not kEmptyChild), as bits.
inline unsigned node_children(const BvhNode& node) {
    return bits(reinterpret_cast<I>(load_u(node.child)) != splat_i(static_cast<std::int32_t>(BvhNode::kEmptyChild)));
}

// Lane i's ray of `w` (WatertightLanes of this namespace's eight lanes, or of the packets' sixteen:
// bvh_packet.inl) as the leaf test reads it.
template <class Lanes>
inline LeafRay leaf_ray_of_lane(const Lanes& w, int i) {
    const float o[3] = {w.org[0][i], w.org[1][i], w.org[2][i]}, s[3] = {w.shear[0][i], w.shear[1][i], w.shear[2][i]};
    return LeafRay(o, s, w.kx[i], w.ky[i], w.kz[i]);
}

// Row i of the result is lane i of each of the eight rows: an 8 x 8 transpose in three rounds of
// eight shuffles (pairs of rows within each half, then quadruples, then the halves).
inline void transpose8(F (&m)[8]) {
    F u[8], v[8];
    for (int k = 0; k < 8; k += 2) {
        u[k] = __builtin_shufflevector(m[k], m[k + 1], 0, 8, 1, 9, 4, 12, 5, 13);
        u[k + 1] = __builtin_shufflevector(m[k], m[k + 1], 2, 10, 3, 11, 6, 14, 7, 15);
    }
    for (int h = 0; h < 8; h += 4) {  // v[h + j]: rows h to h + 3 of lanes j and j + 4
        v[h] = __builtin_shufflevector(u[h], u[h + 2], 0, 1, 8, 9, 4, 5, 12, 13);
        v[h + 1] = __builtin_shufflevector(u[h], u[h + 2], 2, 3, 10, 11, 6, 7, 14, 15);
        v[h + 2] = __builtin_shufflevector(u[h + 1], u[h + 3], 0, 1, 8, 9, 4, 5, 12, 13);
        v[h + 3] = __builtin_shufflevector(u[h + 1], u[h + 3], 2, 3, 10, 11, 6, 7, 14, 15);
    }
    for (int j = 0; j < 4; ++j) {
        m[j] = __builtin_shufflevector(v[j], v[4 + j], 0, 1, 2, 3, 8, 9, 10, 11);
        m[j + 4] = __builtin_shufflevector(v[j], v[4 + j], 4, 5, 6, 7, 12, 13, 14, 15);
    }
}

// Rays [0, n) (n <= kLanes) of a batch prepared in lanes (simd/ray_lanes.inl), written to out[0, n)
// (the records past n get the empty lanes). Returns the lanes of valid rays, as bits. Each lane's
// record goes out as two rows of a transpose: extracted and stored field by field, the records took
// 37 % of prepare_rays' samples on random rays (docs/INCOHERENT.md, "Twenty-second round").
inline unsigned prepare_rays(const Ray* rays, std::size_t n, const Box3& scene, PreparedRay (&out)[kLanes]) {
    const RayLanes l = load_ray_lanes(rays, n, scene);
    const WatertightLanes w(l);
    const I code = (l.negative[0] & 1) | (l.negative[1] & 2) | (l.negative[2] & 4) | w.kx << 3 | w.ky << 5 | w.kz << 7;
    F front[8] = {l.org[0], l.org[1], l.org[2], l.tnear, l.inv[0], l.inv[1], l.inv[2], l.margin};
    F back[8] = {l.axis_margin[0], l.axis_margin[1], l.axis_margin[2], w.shear[0], w.shear[1], w.shear[2],
                 reinterpret_cast<F>(code), splat(0.f)};
    transpose8(front);
    transpose8(back);
    for (int i = 0; i < kLanes; ++i) {
        std::memcpy(&out[i], &front[i], sizeof(F));
        std::memcpy(&out[i].axis_margin, &back[i], sizeof(F));
    }
    return bits(l.valid);
}

// The watertight test of the leaf's lanes against the ray; returns the lanes that meet their
// triangle, with t, u, v.
[[gnu::always_inline]] inline I watertight_leaf(const BvhLeaf& leaf, std::uint32_t count, const LeafRay& r, F& t, F& u,
                                                F& v) {
    // Each vertex's rows from its first (its x row): the ray's axis order picks a row by offset.
    const float* vertex[3] = {leaf.v[0][0], leaf.v[1][0], leaf.v[2][0]};
    const int offset[3] = {r.kx, r.ky, r.kz};
    const I used = splat_i(static_cast<std::int32_t>(count)) > I{0, 1, 2, 3, 4, 5, 6, 7};
    return watertight_in_lanes([&](int k, int role) { return load(vertex[k] + offset[role]); }, r.ox, r.oy, r.oz, r.sx,
                               r.sy, r.sz, used, t, u, v);
}

// The smallest of eight lanes, floats or integers.
template <class V>
inline auto horizontal_min(V x) {
    x = min_lanes(x, __builtin_shufflevector(x, x, 4, 5, 6, 7, 0, 1, 2, 3));
    x = min_lanes(x, __builtin_shufflevector(x, x, 2, 3, 0, 1, 6, 7, 4, 5));
    x = min_lanes(x, __builtin_shufflevector(x, x, 1, 0, 3, 2, 5, 4, 7, 6));
    return x[0];
}

// The lane of `met` with the smallest entry distance: one integer minimum over keys that carry a
// lane's distance in their high bits and its index in the low three, so that the index comes out
// of the minimum itself. The float-then-compare-then-mask it replaces sat on the path to the next
// node's address, about twice as long (docs/INCOHERENT.md, "Tenth round"). A float's bits, with
// the magnitude bits of negatives flipped, order as signed integers as the floats do; dropping the
// low three mantissa bits may swap two children whose distances differ by less than 8 ulp, which
// changes only the order of the visit, never its answer (every child met is visited or culled by
// its exact entry distance). `met` is the box test's lane mask, not its bits, so that the minimum
// need not wait for the bits to come back from a general register as a mask.
inline unsigned nearest_lane(F entry, I met) {
    const I b = reinterpret_cast<I>(entry);
    const I ordered = b ^ ((b >> 31) & 0x7fffffff);
    const I key = (ordered & ~7) | I{0, 1, 2, 3, 4, 5, 6, 7};
    return static_cast<unsigned>(horizontal_min(select(met, key, splat_i(INT32_MAX)))) & 7u;
}

// Tests a leaf for the query: the closest hit by the hit rule among the lanes, or any lane's hit.
// True when an any-hit query is answered.
template <class Query, class Counters>
[[gnu::always_inline]] inline bool test_leaf(const BvhLeaf& leaf, std::uint32_t count, const LeafRay& r, Query& q,
                                             Counters& c) {
    c.leaf();
    for (std::uint32_t i = 0; i < count; ++i) c.triangle();
    F t, u, v;
    const I hit = watertight_leaf(leaf, count, r, t, u, v);
    if constexpr (Query::kAnyHit) {
        return any(hit & (t >= splat(q.tnear)) & (t <= splat(q.tfar)));
    } else {
        // The lanes' closest t by a lane minimum, not a loop over the lanes hit (whose count is
        // data-dependent, hence mispredicted on incoherent rays); equal t falls to the lower index.
        const I accepted = hit & (t >= splat(q.tnear)) & (t <= splat(q.best.t));
        if (!any(accepted)) return false;
        const F candidate = select(accepted, t, splat(kInfinity));
        const float t_min = horizontal_min(candidate);
        unsigned tied = bits(accepted & (candidate == splat(t_min)));
        int i = __builtin_ctz(tied);
        for (tied &= tied - 1; tied; tied &= tied - 1)
            if (leaf.prim[__builtin_ctz(tied)] < leaf.prim[i]) i = __builtin_ctz(tied);
        if (closer(t[i], leaf.prim[i], q.best)) q.best = Hit{t[i], leaf.prim[i], u[i], v[i]};
        return false;
    }
}

// The children that are leaves, as a bit mask (the leaf bit is the sign bit of a child word).
inline unsigned leaf_lanes(const BvhNode& node) {
    const I words = reinterpret_cast<I>(load_u(node.child));
    return bits((words < 0) & (words != -1));
}

// Deep enough for any tree the builder makes: each level pushes at most seven children, and the
// binary tree is at most kSahDepth + log2(2^32) levels deep, the wide one no deeper. A push writes
// a whole row of eight, hence the slack above the top.
inline constexpr int kBvhStackSize = 7 * 96 + 1;
inline constexpr int kBvhStackSlack = kBvhWidth;

#if defined(CELLRT_SIMD_AVX2)
// For each 8-bit mask, the indices of its set bits in ascending order, a byte each: the lane
// permutation that packs the chosen lanes to the front. AVX2 has no compressing store (AVX-512's
// vpcompressd); a permutation from this table does the same without a loop over the bits, whose
// trip count an incoherent ray's branch predictor cannot learn.
struct PackTable {
    std::uint64_t order[256];
    constexpr PackTable() : order{} {
        for (unsigned m = 0; m < 256; ++m)
            for (unsigned i = 0, n = 0; i < 8; ++i)
                if (m >> i & 1) order[m] |= std::uint64_t{i} << (8 * n++);
    }
};
inline constexpr PackTable kPackTable{};
#endif

// Pushes the children of `met`: their words and, where `entry_stack` is given, their entry distances.
inline void push_children(const BvhNode& node, unsigned met, F entries, std::uint32_t* word_stack, float* entry_stack,
                          int& size) {
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2)
    const auto words = reinterpret_cast<__m256i>(load_u(node.child));
    const auto lanes = reinterpret_cast<__m256>(entries);
#endif
#if defined(CELLRT_SIMD_AVX512)
    // Compressed in a register, then stored as a whole row (the stack's slack takes the lanes past
    // the children): on Zen 4 the compress with a memory operand is microcoded; it held 31 % (closest
    // hit) and 18 % (any hit) of the paired walks' samples on random rays, and the walks now take 0.55
    // to 0.88 of their time (docs/INCOHERENT.md, "Twenty-first round").
    const auto mask = static_cast<__mmask8>(met);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(word_stack + size), _mm256_maskz_compress_epi32(mask, words));
    if (entry_stack) _mm256_storeu_ps(entry_stack + size, _mm256_maskz_compress_ps(mask, lanes));
#elif defined(CELLRT_SIMD_AVX2)
    const __m256i order = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(kPackTable.order[met])));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(word_stack + size), _mm256_permutevar8x32_epi32(words, order));
    if (entry_stack) _mm256_storeu_ps(entry_stack + size, _mm256_permutevar8x32_ps(lanes, order));
#else
    for (unsigned m = met, n = size; m; m &= m - 1, ++n) {
        word_stack[n] = node.child[__builtin_ctz(m)];
        if (entry_stack) entry_stack[n] = entries[__builtin_ctz(m)];
    }
#endif
    size += __builtin_popcount(met);
}

// How a step left its ray's walk.
enum class BvhStep { on, done, answered };

// One step of a ray's walk through the tree: the node or leaf at `word`, then the next word, from the
// node or from the stack (`size` children on it). `done` when the stack runs out, `answered` when an
// any-hit query is. The walk's word and stack size are the caller's locals, passed by reference to
// this inlined step, so that they stay in registers (members of a walk in memory cost 11 % more
// instructions: docs/INCOHERENT.md, "Eleventh round").
template <class Query, class Counters>
[[gnu::always_inline]] inline BvhStep bvh_step(const BvhNode* nodes, const BvhLeaf* leaves, const BoxRay& box_ray,
                                               const LeafRay& leaf_ray, Query& q, std::uint32_t& word, int& size,
                                               std::uint32_t* word_stack, float* entry_stack, Counters& c) {
    // An any-hit query's cull distance is fixed (tfar plus the margin) and every child it pushes was met
    // within it, so its stack needs no entry distances and no pop is culled.
    constexpr bool kCulls = !Query::kAnyHit;
    if (BvhNode::is_leaf(word)) {
        if (test_leaf(leaves[BvhNode::leaf_index(word)], BvhNode::leaf_count(word), leaf_ray, q, c))
            return BvhStep::answered;
    } else {
        c.node();
        const BvhNode& node = nodes[word];
        F entry;
        const I met_lanes = meet_children_lanes(node, box_ray, q.cull_t(), entry);
        const unsigned met = bits(met_lanes);
        if (met) {
            // One child met (the common case deep in the tree): go there. Several: the nearest goes
            // first, the others wait unsorted (sorting them costs more on incoherent rays than the
            // order saves, and a popped child past the answer is skipped). An any-hit query takes the
            // first child met, as Embree's any-hit traversal does: any occluder answers it, and the
            // next node's address then waits on no lane minimum (measured faster than the nearest,
            // and than testing the leaves met first: docs/INCOHERENT.md, "Third round").
            if ((met & (met - 1)) == 0) {
                word = node.child[__builtin_ctz(met)];
                return BvhStep::on;
            }
            unsigned next = __builtin_ctz(met);
            if constexpr (!Query::kAnyHit) next = nearest_lane(entry, met_lanes);
            word = node.child[next];
            push_children(node, met & ~(1u << next), entry, word_stack, kCulls ? entry_stack : nullptr, size);
            return BvhStep::on;
        }
    }
    for (;;) {
        if (size == 0) return BvhStep::done;
        --size;
        if constexpr (kCulls) {
            if (entry_stack[size] > q.cull_t()) continue;
        }
        break;
    }
    word = word_stack[size];
    return BvhStep::on;
}

// A ray's stacks: child words and, for a closest-hit query, their entry distances.
template <class Query>
struct BvhStacks {
    std::uint32_t words[kBvhStackSize + kBvhStackSlack];
    float entries[Query::kAnyHit ? 1 : kBvhStackSize + kBvhStackSlack];
};

// A walk to its end from where it stands (`word`, with `size` children on `stacks`); true when an
// any-hit query is answered.
template <class Query, class Counters>
[[gnu::always_inline]] inline bool traverse_bvh_from_walk(const BvhNode* nodes, const BvhLeaf* leaves,
                                                          const BoxRay& box_ray, const LeafRay& leaf_ray, Query& q,
                                                          std::uint32_t word, int size, BvhStacks<Query>& stacks,
                                                          Counters& c) {
    for (;;) {
        const BvhStep s = bvh_step(nodes, leaves, box_ray, leaf_ray, q, word, size, stacks.words, stacks.entries, c);
        if (s != BvhStep::on) return s == BvhStep::answered;
    }
}

// One ray through the subtree of `root` (an inner node's word; 0 is the whole tree's root).
template <class Query, class Counters>
bool traverse_bvh_from(const BvhNode* nodes, const BvhLeaf* leaves, const BoxRay& box_ray, const LeafRay& leaf_ray,
                       std::uint32_t root, Query& q, Counters& c) {
    BvhStacks<Query> stacks;
    return traverse_bvh_from_walk(nodes, leaves, box_ray, leaf_ray, q, root, 0, stacks, c);
}

// Two rays from the subtree of `root`, their walks interleaved step by step (as paired_batch, below,
// over a batch): the streams' leftover rays (bvh_stream.inl) go on this way. Sets `answered_a` and
// `answered_b` for any-hit queries answered.
template <class Query, class Counters>
void traverse_two_from(const BvhNode* nodes, const BvhLeaf* leaves, std::uint32_t root, const BoxRay& box_a,
                       const LeafRay& leaf_a, Query& q_a, bool& answered_a, const BoxRay& box_b, const LeafRay& leaf_b,
                       Query& q_b, bool& answered_b, Counters& c) {
    BvhStacks<Query> stack_a, stack_b;
    std::uint32_t word_a = root, word_b = root;
    int size_a = 0, size_b = 0;
    for (;;) {
        BvhStep s = bvh_step(nodes, leaves, box_a, leaf_a, q_a, word_a, size_a, stack_a.words, stack_a.entries, c);
        if (s != BvhStep::on) [[unlikely]] {
            answered_a = s == BvhStep::answered;
            answered_b = traverse_bvh_from_walk(nodes, leaves, box_b, leaf_b, q_b, word_b, size_b, stack_b, c);
            return;
        }
        s = bvh_step(nodes, leaves, box_b, leaf_b, q_b, word_b, size_b, stack_b.words, stack_b.entries, c);
        if (s != BvhStep::on) [[unlikely]] {
            answered_b = s == BvhStep::answered;
            answered_a = traverse_bvh_from_walk(nodes, leaves, box_a, leaf_a, q_a, word_a, size_a, stack_a, c);
            return;
        }
    }
}

// The answers for a tree without triangles: nothing is hit.
template <class Answer>
void miss_all(std::span<const Ray> rays, std::span<Answer> out, TraversalCounters* counters) {
    std::fill(out.begin(), out.end(), Answer{});
    if (counters) counters->rays += rays.size();
}

// Two rays' walks interleaved step by step on one thread. A random ray's steps wait on memory, each
// node's address on the last node's bytes; one walk at a time keeps one such load in flight. With
// the steps of two independent walks in turn, the core issues one walk's load while the other's
// waits (and a load issued under a mispredicted branch still fetches its line), so two misses
// overlap: the group prefetching of Chen, Ailamaki, Gibbons and Mowry, "Improving Hash Join
// Performance through Prefetching" (ICDE 2004), applied to traversal. Each walk is the single-ray
// walk above, step for step, so the answers are its answers. `answer(i, query, step)` is called once
// per ray of the batch: with a null query for an invalid ray (ray.hpp), which hits nothing.
template <class Query, class Counters, class Answer>
void paired_batch(const BvhTree& tree, std::span<const Ray> rays, Counters& c, Answer&& answer) {
    constexpr std::size_t kNone = ~std::size_t{0};
    // A walk's ray as the steps see it; its word and stack size are locals of the loop below.
    struct Walk {
        BoxRay box;
        LeafRay leaf;
        Query q;
    };
    const BvhNode* nodes = tree.nodes.data();
    const BvhLeaf* leaves = tree.leaves.data();
    BvhStacks<Query> stack_a, stack_b;
    // The rays are set up eight at a time in lanes (prepare_rays), as the walks reach them.
    PreparedRay prepared[kLanes];
    unsigned prepared_valid = 0;
    std::size_t next = 0;
    // The batch's next valid ray, answering the invalid ones on the way; kNone when none is left.
    const auto take = [&]() {
        for (; next < rays.size(); ++next) {
            if (next % kLanes == 0)
                prepared_valid = prepare_rays(&rays[next], std::min<std::size_t>(kLanes, rays.size() - next),
                                              tree.bounds, prepared);
            if (prepared_valid >> next % kLanes & 1) return next++;
            answer(next, static_cast<const Query*>(nullptr), BvhStep::done);
        }
        return kNone;
    };
    // The walk of the ray take() returned last.
    const auto walk = [&](std::size_t i) {
        const PreparedRay& r = prepared[i % kLanes];
        return Walk{r.box(), r.leaf(), Query(r.tnear, finite_tfar(rays[i].tfar), r.margin)};
    };
    // The walk left when the batch runs out goes on alone.
    const auto finish = [&](std::size_t i, Walk& w, std::uint32_t word, int size, BvhStacks<Query>& st) {
        const bool answered = traverse_bvh_from_walk(nodes, leaves, w.box, w.leaf, w.q, word, size, st, c);
        answer(i, &w.q, answered ? BvhStep::answered : BvhStep::done);
    };
    std::size_t ia = take();
    if (ia == kNone) return;
    Walk a = walk(ia);
    std::size_t ib = take();
    if (ib == kNone) return finish(ia, a, 0u, 0, stack_a);
    Walk b = walk(ib);
    std::uint32_t word_a = 0, word_b = 0;
    int size_a = 0, size_b = 0;
    for (;;) {
        BvhStep s = bvh_step(nodes, leaves, a.box, a.leaf, a.q, word_a, size_a, stack_a.words, stack_a.entries, c);
        if (s != BvhStep::on) [[unlikely]] {
            answer(ia, &a.q, s);
            if ((ia = take()) == kNone) return finish(ib, b, word_b, size_b, stack_b);
            a = walk(ia);
            word_a = 0;
            size_a = 0;
        }
        s = bvh_step(nodes, leaves, b.box, b.leaf, b.q, word_b, size_b, stack_b.words, stack_b.entries, c);
        if (s != BvhStep::on) [[unlikely]] {
            answer(ib, &b.q, s);
            if ((ib = take()) == kNone) return finish(ia, a, word_a, size_a, stack_a);
            b = walk(ib);
            word_b = 0;
            size_b = 0;
        }
    }
}

// The batch entry points: one kernel per query, over a batch. The root's box test is the scene box
// test, so rays are not clipped to the scene first.
inline void closest_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<Hit> hits,
                          TraversalCounters* counters) {
    if (tree.nodes.empty()) return miss_all(rays, hits, counters);
    closest_hits(tree.bounds, rays, hits, counters, [&](const TraversalRay& r, ClosestHit& q, auto& count) {
        return traverse_bvh_from(tree.nodes.data(), tree.leaves.data(), BoxRay(r), LeafRay(r.watertight), 0, q, count);
    });
}

inline void any_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                      TraversalCounters* counters) {
    if (tree.nodes.empty()) return miss_all(rays, occluded, counters);
    any_hits(tree.bounds, rays, occluded, counters, [&](const TraversalRay& r, AnyHit& q, auto& count) {
        return traverse_bvh_from(tree.nodes.data(), tree.leaves.data(), BoxRay(r), LeafRay(r.watertight), 0, q, count);
    });
}

// The same, two rays at a time (paired_batch).
inline void closest_paired_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<Hit> hits,
                                 TraversalCounters* counters) {
    if (tree.nodes.empty()) return miss_all(rays, hits, counters);
    with_counters(counters, rays.size(), [&](auto& count) {
        paired_batch<ClosestHit>(tree, rays, count, [&](std::size_t i, const ClosestHit* q, BvhStep) {
            hits[i] = q ? q->result() : Hit{};
        });
    });
}

inline void any_paired_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                             TraversalCounters* counters) {
    if (tree.nodes.empty()) return miss_all(rays, occluded, counters);
    with_counters(counters, rays.size(), [&](auto& count) {
        paired_batch<AnyHit>(tree, rays, count, [&](std::size_t i, const AnyHit*, BvhStep s) {
            occluded[i] = s == BvhStep::answered ? 1 : 0;
        });
    });
}

// Fetches the lines of a child that a packet or a stream pushes (four of a node, five of a leaf), so
// that they arrive while it goes down its nearest child; one ray at a time has too little to do in
// between. Measured (docs/INCOHERENT.md, "Twelfth round"): the BVH's packets trace a frame's shadow
// rays 12 to 16 % faster and AO rays 5 to 8 %; the same prefetch of the child a single ray pushed
// last gained nothing.
inline void prefetch_child(const BvhNode* nodes, const BvhLeaf* leaves, std::uint32_t word) {
    static_assert(sizeof(BvhNode) == 4 * 64 && sizeof(BvhLeaf) == 5 * 64);
    const bool leaf = BvhNode::is_leaf(word);
    const char* p = leaf ? reinterpret_cast<const char*>(&leaves[BvhNode::leaf_index(word)])
                         : reinterpret_cast<const char*>(&nodes[word]);
    for (int i = 0; i < (leaf ? 5 : 4); ++i) __builtin_prefetch(p + 64 * i);
}

#include "bvh/bvh_stream.inl"

// This namespace's kernels as the registry's table, with the packets' entry points and width from
// the namespace that includes bvh_packet.inl: this one (eight rays) or, with AVX-512, the unit's
// sixteen-lane one.
inline BvhKernels bvh_kernel_table(const char* isa, decltype(BvhKernels::packet_closest) packet_closest,
                                   decltype(BvhKernels::packet_any) packet_any, int packet_rays) {
    return {&closest_batch, &any_batch,   &closest_stream_batch, &any_stream_batch,  packet_closest,
            packet_any,     packet_rays,  &closest_paired_batch, &any_paired_batch,  isa};
}
