// Ray streams over the wide BVH (issue 18, part 4; after Wald, Gribble, Boulos, Kensler 2007, "SIMD
// ray stream tracing", and Barringer & Akenine-Möller 2014, "Dynamic ray stream traversal"): a batch
// of rays goes down the tree together. A node is read once for the whole stream that reaches it and
// tested against each of its rays in turn (the single-ray kernel's eight-wide box test, while the
// node's four lines stay in the first-level cache), and the stream is split into one stream per
// child met, each ray keeping its entry distance. A leaf is likewise read once and tested against
// every ray of its stream. The tree is walked depth first; each stream visits the children of a node
// nearest first along its rays' common direction octant (closest hit: the batch is split by octant
// first, so that the order is every ray's near-to-far order on each axis's sign), and a ray whose best
// hit has come nearer than its entry into a waiting child is dropped from that child's stream, as the
// single-ray kernel skips a popped child. An any-hit ray leaves every stream once it is answered.
//
// A stream of a few rays (kSingleBelow) goes on as single rays from the node it reached, each with
// the query it carries, as Embree's hybrid packets fall back to single rays when few lanes are left;
// two walks at a time (traverse_two_from).
//
// The tests are bvh_kernels.inl's, lane for lane, and every ray ends with the hit rule's answer among
// the triangles of the leaves it reached; a leaf is skipped only when the single-ray kernel would skip
// it too (it starts past the ray's cull distance), whatever the order. So the answers are exactly
// the single-ray kernel's, hence brute force's.
//
// No include guard: included after bvh_kernels.inl in each instruction set's namespace.

// A stream of at most this many rays goes on as single rays, two walks at a time (bvh_kernels.inl),
// from the node it reached: below it the stream's bookkeeping costs more than the node's shared lines save (Sponza,
// 2026-12-02, docs/INCOHERENT.md "Ray streams": 0 to 4 lose on diffuse bounces, 8 and 16 win on AO).
inline constexpr std::uint32_t kSingleBelow = 8;

// A ray of a node's stream and the distance at which it enters that node.
struct StreamEntry {
    std::uint32_t ray;
    float entry;
};

// A node waiting with its stream: entries [begin, begin + count) of the scratch's arena.
struct StreamFrame {
    std::uint32_t word, begin, count;
};

// What a batch's streams need, kept per thread and reused (grown, never shrunk), so that a batch
// allocates nothing once a thread has traced one as large.
struct StreamScratch {
    std::vector<PreparedRay> rays;      // the batch's valid rays, by octant
    std::vector<std::uint32_t> index;   // each one's place in the batch
    std::vector<ClosestHit> closest;    // their queries
    std::vector<AnyHit> any;
    std::vector<std::uint8_t> done;     // any hit: answered
    std::vector<StreamEntry> arena;     // the waiting streams, as a stack
    std::vector<std::uint32_t> met_ray; // a node's rays that met some child, their children and entries
    std::vector<std::uint8_t> met;
    std::vector<float> met_entry;        // eight per ray (floats: a vector of F is not 32-byte aligned)
};

inline StreamScratch& stream_scratch() {
    thread_local StreamScratch s;
    return s;
}

// Walks one stream, rays [first, first + count) of the scratch, from the root. `order` holds the sign
// bits of the direction that orders the children (nearest first along it).
template <class Query, class Counters>
void trace_stream(const BvhNode* nodes, const BvhLeaf* leaves, StreamScratch& s, Query* queries, std::uint32_t first,
                  std::uint32_t count, unsigned order, Counters& c) {
    constexpr bool kAny = Query::kAnyHit;
    const PreparedRay* rays = s.rays.data();
    std::uint8_t* done = s.done.data();
    if (s.arena.size() < std::size_t{count} * kBvhWidth) s.arena.resize(std::size_t{count} * kBvhWidth);
    for (std::uint32_t i = 0; i < count; ++i) s.arena[i] = {first + i, -kInfinity};
    StreamFrame frames[kBvhStackSize + kBvhStackSlack];
    int size = 0;
    frames[size++] = {0, 0, count};
    // The sign of each axis of the order, as a lane factor: nearest along `order` is the smallest key.
    const F sign[3] = {splat(order & 1u ? -1.f : 1.f), splat(order & 2u ? -1.f : 1.f), splat(order & 4u ? -1.f : 1.f)};
    while (size > 0) {
        const StreamFrame f = frames[--size];
        StreamEntry* arena = s.arena.data();
        if (BvhNode::is_leaf(f.word)) {
            const BvhLeaf& leaf = leaves[BvhNode::leaf_index(f.word)];
            const std::uint32_t n = BvhNode::leaf_count(f.word);
            for (std::uint32_t j = f.begin; j < f.begin + f.count; ++j) {
                const std::uint32_t k = arena[j].ray;
                if constexpr (kAny) {
                    if (done[k]) continue;
                } else {
                    if (arena[j].entry > queries[k].cull_t()) continue;
                }
                if (test_leaf(leaf, n, rays[k].leaf(), queries[k], c)) done[k] = 1;
            }
            continue;
        }
        if (f.count <= kSingleBelow) {
            // Too few rays left to share the node's lines: each goes on with its own walk from this
            // node, with the query it has carried so far, two walks at a time (traverse_two_from).
            std::uint32_t waiting = ~0u;  // a ray waiting for a second
            for (std::uint32_t j = f.begin; j < f.begin + f.count; ++j) {
                const std::uint32_t k = arena[j].ray;
                if constexpr (kAny) {
                    if (done[k]) continue;
                } else {
                    if (arena[j].entry > queries[k].cull_t()) continue;
                }
                if (waiting == ~0u) {
                    waiting = k;
                    continue;
                }
                bool answered_a = false, answered_b = false;
                traverse_two_from(nodes, leaves, f.word, rays[waiting].box(), rays[waiting].leaf(), queries[waiting],
                                  answered_a, rays[k].box(), rays[k].leaf(), queries[k], answered_b, c);
                if (answered_a) done[waiting] = 1;
                if (answered_b) done[k] = 1;
                waiting = ~0u;
            }
            if (waiting != ~0u &&
                traverse_bvh_from(nodes, leaves, rays[waiting].box(), rays[waiting].leaf(), f.word, queries[waiting], c))
                done[waiting] = 1;
            continue;
        }
        const BvhNode& node = nodes[f.word];
        std::uint32_t* met_ray = s.met_ray.data();
        std::uint8_t* met = s.met.data();
        float* met_entry = s.met_entry.data();
        std::uint32_t m = 0;
        I counts = splat_i(0);  // rays per child (subtracting the lane masks of -1)
        unsigned met_any = 0;
        for (std::uint32_t j = f.begin; j < f.begin + f.count; ++j) {
            const std::uint32_t k = arena[j].ray;
            if constexpr (kAny) {
                if (done[k]) continue;
            } else {
                if (arena[j].entry > queries[k].cull_t()) continue;
            }
            c.node();
            F entry;
            const unsigned hit = meet_children(node, rays[k].box(), queries[k].cull_t(), entry);
            if (!hit) continue;
            met_ray[m] = k;
            met[m] = static_cast<std::uint8_t>(hit);
            *reinterpret_cast<FRow*>(met_entry + std::size_t{m} * kBvhWidth) = entry;
            ++m;
            met_any |= hit;
            counts -= met_mask(hit);
        }
        if (m == 0) continue;
        // The children met, farthest first: pushed first, popped last. An any-hit stream takes the
        // leaves first (they can end rays; subtrees only lead to leaves).
        const float* lo = &node.lo[0][0];
        const float* hi = &node.hi[0][0];
        F key = sign[0] * (load(lo) + load(hi)) + sign[1] * (load(lo + kBvhWidth) + load(hi + kBvhWidth)) +
                sign[2] * (load(lo + 2 * kBvhWidth) + load(hi + 2 * kBvhWidth));
        if constexpr (kAny) key = select(met_mask(leaf_lanes(node)), splat(-kInfinity), key);
        int pushed[kBvhWidth], n_pushed = 0;
        for (unsigned left = met_any; left; ++n_pushed) {
            int far = __builtin_ctz(left);
            for (unsigned b = left & (left - 1); b; b &= b - 1)
                if (key[__builtin_ctz(b)] > key[far]) far = __builtin_ctz(b);
            pushed[n_pushed] = far;
            left &= ~(1u << far);
        }
        std::uint32_t top = f.begin;
        for (int i = 0; i < n_pushed; ++i) top += static_cast<std::uint32_t>(counts[pushed[i]]);
        if (s.arena.size() <= top) {  // the compaction below writes one entry past the end
            s.arena.resize(std::max<std::size_t>(top + 1, 2 * s.arena.size()));
            arena = s.arena.data();
        }
        // Each child's stream, compacted without a branch on the rays' masks (data-dependent, so
        // mispredicted on incoherent rays): every ray is written, and the end moves on only past the
        // ones that met the child.
        top = f.begin;
        for (int i = 0; i < n_pushed; ++i) {
            const int child = pushed[i];
            frames[size++] = {node.child[child], top, static_cast<std::uint32_t>(counts[child])};
            prefetch_child(nodes, leaves, node.child[child]);
            std::uint32_t end = top;
            for (std::uint32_t r = 0; r < m; ++r) {
                arena[end] = {met_ray[r], met_entry[std::size_t{r} * kBvhWidth + child]};
                end += met[r] >> child & 1u;
            }
            top = end;
        }
    }
}

// The direction's sign bits, as TraversalRay::dir_neg holds them.
inline unsigned octant_of(const Vec3& d) {
    return unsigned(std::signbit(d.x)) | unsigned(std::signbit(d.y)) << 1 | unsigned(std::signbit(d.z)) << 2;
}

// Prepares the batch's valid rays (grouped by octant when `by_octant`, else in one group) and their
// queries. Returns how many are valid; ends[o] is where octant o's group ends (by_octant), ends[0]
// the one group's end otherwise.
template <class Query>
std::uint32_t prepare_stream(const BvhTree& tree, std::span<const Ray> rays, StreamScratch& s,
                             std::vector<Query>& queries, bool by_octant, std::uint32_t (&ends)[8]) {
    const std::size_t n = rays.size();
    s.rays.resize(n);
    s.index.resize(n);
    s.done.assign(n, 0);
    s.met_ray.resize(n);
    s.met.resize(n);
    s.met_entry.resize(n * kBvhWidth);
    if (queries.size() < n) queries.resize(n, Query(TraversalRay(Ray{}, tree.bounds)));
    std::uint32_t counts[8] = {};
    if (by_octant)
        for (const Ray& r : rays)
            if (is_valid(r)) ++counts[octant_of(r.dir)];
    std::uint32_t at[8], sum = 0;
    for (int o = 0; o < 8; ++o) {
        at[o] = sum;
        sum += counts[o];
        ends[o] = sum;
    }
    std::uint32_t valid = 0;
    PreparedRay group[kLanes];
    for (std::size_t first = 0; first < n; first += kLanes) {
        const std::size_t m = std::min<std::size_t>(kLanes, n - first);
        for (unsigned lanes = prepare_rays(&rays[first], m, tree.bounds, group); lanes; lanes &= lanes - 1) {
            const unsigned i = static_cast<unsigned>(__builtin_ctz(lanes));
            const std::uint32_t k = by_octant ? at[group[i].octant()]++ : valid;
            ++valid;
            s.rays[k] = group[i];
            s.index[k] = static_cast<std::uint32_t>(first + i);
            queries[k] = Query(group[i].tnear, finite_tfar(rays[first + i].tfar), group[i].margin);
        }
    }
    if (!by_octant) ends[0] = valid;
    return valid;
}

// The batch entry points of the stream traversal.
inline void closest_stream_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<Hit> hits,
                                 TraversalCounters* counters) {
    if (tree.nodes.empty()) return miss_all(rays, hits, counters);
    StreamScratch& s = stream_scratch();
    std::uint32_t ends[8];
    const std::uint32_t valid = prepare_stream(tree, rays, s, s.closest, true, ends);
    std::fill(hits.begin(), hits.end(), Hit{});
    with_counters(counters, rays.size(), [&](auto& count) {
        for (unsigned o = 0, begin = 0; o < 8; begin = ends[o++])
            if (ends[o] > begin)
                trace_stream(tree.nodes.data(), tree.leaves.data(), s, s.closest.data(), begin, ends[o] - begin, o, count);
    });
    for (std::uint32_t k = 0; k < valid; ++k) hits[s.index[k]] = s.closest[k].result();
}

inline void any_stream_batch(const BvhTree& tree, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                             TraversalCounters* counters) {
    if (tree.nodes.empty()) return miss_all(rays, occluded, counters);
    StreamScratch& s = stream_scratch();
    std::uint32_t ends[8];
    const std::uint32_t valid = prepare_stream(tree, rays, s, s.any, false, ends);
    // The order: the sign of the rays' summed direction on each axis.
    float sum[3] = {0.f, 0.f, 0.f};
    for (std::uint32_t k = 0; k < valid; ++k)
        for (int a = 0; a < 3; ++a) sum[a] += rays[s.index[k]].dir[a] > 0.f ? 1.f : -1.f;
    const unsigned order = (sum[0] < 0.f) | (sum[1] < 0.f) << 1 | (sum[2] < 0.f) << 2;
    std::fill(occluded.begin(), occluded.end(), std::uint8_t{0});
    with_counters(counters, rays.size(), [&](auto& count) {
        if (valid > 0) trace_stream(tree.nodes.data(), tree.leaves.data(), s, s.any.data(), 0, valid, order, count);
    });
    for (std::uint32_t k = 0; k < valid; ++k) occluded[s.index[k]] = s.done[k];
}
