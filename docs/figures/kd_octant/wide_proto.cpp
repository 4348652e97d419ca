// Seventeenth round (docs/INCOHERENT.md), tried and not kept: the kd-tree traversed two levels at a
// time, its inner nodes and their children collapsed into nodes of three planes and four cells (empty
// leaves dropped at the collapse), against TA_rec (`kd:rec`) and a copy of the interval traversal
// (`br2`) on one scene's camera rays, with every hit compared to TA_rec's. BRANCHY pushes the cells
// a ray reaches with branches, without it branch-free (the study's style); RAYREF and DIRNEG put
// back, in `br2`, reads of the ray's origin and reciprocal direction through the ray and of the
// near child's side from dir_neg[] (the change kept reads it from a register). Build and run from
// the repository root, after the library (build/libcellrt.a):
//   g++ -DBRANCHY -std=c++20 -O3 -DNDEBUG -ffp-contract=off -Iinclude -Isrc \
//       docs/figures/kd_octant/wide_proto.cpp build/libcellrt.a -ltbb -lpthread -o /tmp/wide_proto
//   /tmp/wide_proto ../shared/scenes/bunny/bunny.json 512
#include <bit>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>
#include "cellrt/camera.hpp"
#include "cellrt/scene.hpp"
#include "kdtree/kd_structure.hpp"

using namespace cellrt;
using namespace cellrt::detail;

struct alignas(16) WideNode {
    float split[3];          // top plane, then the planes of child pair 0 and 1 (NaN: the child is a leaf)
    std::uint32_t axes;      // bits 0-1 top, 2-3 pair 0, 4-5 pair 1, bits 8-11 slots that hold a cell
    KdNode child[4];         // slot 2*p + k: pair p's child k; inner: children() = wide index
};
static_assert(sizeof(WideNode) == 48);

struct WideTree {
    std::vector<WideNode> nodes;
    KdNode root;
};

static std::uint32_t collapse(const KdTree& t, std::uint32_t i, std::vector<WideNode>& out) {
    const std::uint32_t w = out.size();
    out.emplace_back();
    const KdNode n = t.nodes[i];
    WideNode wn{};
    wn.split[0] = n.split();
    wn.axes = n.axis();
    std::uint32_t present = 0;
    KdNode kids[4];
    std::uint32_t inner_at[4] = {~0u, ~0u, ~0u, ~0u};
    for (int p = 0; p < 2; ++p) {
        const KdNode c = t.nodes[n.children() + p];
        if (c.is_leaf()) {
            wn.split[1 + p] = std::nanf("");
            kids[2 * p] = kids[2 * p + 1] = c;
            if (c.count() > 0) present |= 1u << (2 * p);
        } else {
            wn.split[1 + p] = c.split();
            wn.axes |= std::uint32_t(c.axis()) << (2 + 2 * p);
            for (int k = 0; k < 2; ++k) {
                const KdNode g = t.nodes[c.children() + k];
                kids[2 * p + k] = g;
                if (!g.is_leaf()) inner_at[2 * p + k] = c.children() + k;
                if (!g.is_leaf() || g.count() > 0) present |= 1u << (2 * p + k);
            }
        }
    }
    wn.axes |= present << 8;
    out[w] = wn;
    for (int s = 0; s < 4; ++s) {
        if (inner_at[s] != ~0u) {
            const std::uint32_t sub = collapse(t, inner_at[s], out);
            kids[s] = KdNode::inner(0, 0.f, sub);
        }
    }
    for (int s = 0; s < 4; ++s) out[w].child[s] = kids[s];
    return w;
}

static WideTree make_wide(const KdTree& t) {
    WideTree w;
    if (t.nodes[0].is_leaf()) { w.root = t.nodes[0]; return w; }
    w.root = KdNode::inner(0, 0.f, collapse(t, 0, w.nodes));
    return w;
}

struct WEntry { std::uint64_t bits; float tmin, tmax;
  WEntry() {}
  WEntry(KdNode n, float a, float b) : bits(std::bit_cast<std::uint64_t>(n)), tmin(a), tmax(b) {}
  KdNode node() const { return std::bit_cast<KdNode>(bits); } };

template <class Query, class Counters>
bool traverse_wide(const WideTree& wt, const KdTree& tree, DirectMemory<KdNode>& mem, const TraversalRay& r, Query& q, Counters& c) {
    float tmin, tmax;
    if (!r.clip(tree.bounds, tmin, tmax)) return false;
    KdTraits::Leaves leaves;
    WEntry stack[3 * 32 + 4];
    int sp = 0;
    KdNode cur = wt.root;
    const float m = r.margin;
    for (;;) {
        while (!cur.is_leaf()) {
            c.node();
            const WideNode& W = wt.nodes[cur.children()];
            const std::uint32_t ax = W.axes;
            const int a0 = ax & 3;
            const std::uint32_t sn = r.dir_neg[a0];
            const float t0 = (W.split[0] - r.org[a0]) * r.inv_dir[a0];
            const int aN = (ax >> (2 + 2 * sn)) & 3, aF = (ax >> (2 + 2 * (sn ^ 1))) & 3;
            const std::uint32_t sN = r.dir_neg[aN], sF = r.dir_neg[aF];
            const float tN = (W.split[1 + sn] - r.org[aN]) * r.inv_dir[aN];
            const float tF = (W.split[2 - sn] - r.org[aF]) * r.inv_dir[aF];
            const bool vN = !(tmin > t0 + m), vF = !(t0 - m > tmax);
            const float loN = tmin, hiN = min_keep(tmax, t0 + m);
            const float loF = max_keep(tmin, t0 - m), hiF = tmax;
            const std::uint32_t present = ax >> 8;
            const std::uint32_t s0 = 2 * sn + sN, s1 = s0 ^ 1, s2 = 2 * (sn ^ 1) + sF, s3 = s2 ^ 1;
            const std::uint32_t v0 = std::uint32_t(vN) & std::uint32_t(!(loN > tN + m)) & (present >> s0);
            const std::uint32_t v1 = (std::uint32_t(vN) & std::uint32_t(!(tN - m > hiN)) & (present >> s1)) & 1u;
            const std::uint32_t v2 = (std::uint32_t(vF) & std::uint32_t(!(loF > tF + m)) & (present >> s2)) & 1u;
            const std::uint32_t v3 = (std::uint32_t(vF) & std::uint32_t(!(tF - m > hiF)) & (present >> s3)) & 1u;
#ifdef BRANCHY
            if (v3) stack[sp++] = {W.child[s3], max_keep(loF, tF - m), hiF};
            if (v2) stack[sp++] = {W.child[s2], loF, min_keep(hiF, tF + m)};
            if (v1) stack[sp++] = {W.child[s1], max_keep(loN, tN - m), hiN};
#else
            stack[sp] = {W.child[s3], max_keep(loF, tF - m), hiF};
            sp += v3;
            stack[sp] = {W.child[s2], loF, min_keep(hiF, tF + m)};
            sp += v2;
            stack[sp] = {W.child[s1], max_keep(loN, tN - m), hiN};
            sp += v1;
#endif
            if (v0 & 1u) {
                cur = W.child[s0];
                tmin = loN;
                tmax = min_keep(hiN, tN + m);
            } else {
                do {
                    if (sp == 0) return false;
                    --sp;
                } while (stack[sp].tmin > q.cull_t());
                cur = stack[sp].node(); tmin = stack[sp].tmin; tmax = stack[sp].tmax;
            }
        }
        if (leaves.test(cur, mem, r, q, c)) return true;
        do {
            if (sp == 0) return false;
            --sp;
        } while (stack[sp].tmin > q.cull_t());
        cur = stack[sp].node(); tmin = stack[sp].tmin; tmax = stack[sp].tmax;
    }
}


template <class Query, class Memory, class Counters>
bool traverse_br2(const KdTree& tree, Memory& mem, const TraversalRay& r, Query& q, Counters& c) {
    float tmin, tmax;
    if (!r.clip(tree.bounds, tmin, tmax)) return false;
    const std::uint32_t signs = r.dir_neg[0] | r.dir_neg[1] << 1 | r.dir_neg[2] << 2;
    const float m = r.margin;
    const float org[4] = {r.org.x, r.org.y, r.org.z, 0.f}, inv[4] = {r.inv_dir.x, r.inv_dir.y, r.inv_dir.z, 0.f};
    typename KdTraits::Leaves leaves;
    struct E { std::uint32_t node; float tmin, tmax; E() {} E(std::uint32_t n, float a, float b) : node(n), tmin(a), tmax(b) {} };
    E stack[kKdMaxDepth + 1];
    int sp = 0;
    std::uint32_t index = 0;
    for (;;) {
        KdNode n = mem.node(index);
        while (!n.is_leaf()) {
            c.node();
            const int a = n.axis();
#ifdef DIRNEG
            const std::uint32_t s = r.dir_neg[a];
#else
            const std::uint32_t s = (signs >> a) & 1u;
#endif
#ifdef RAYREF
            const float t = (n.split() - r.org[a]) * r.inv_dir[a];
#else
            const float t = (n.split() - org[a]) * inv[a];
#endif
            const bool near_ok = !(tmin > t + m), far_ok = !(t - m > tmax);
            if (near_ok) {
                if (far_ok) stack[sp++] = E(n.children() + (s ^ 1u), max_keep(tmin, t - m), tmax);
                tmax = min_keep(tmax, t + m);
                index = n.children() + s;
            } else {
                tmin = max_keep(tmin, t - m);
                index = n.children() + (s ^ 1u);
            }
            n = mem.node(index);
        }
        if (leaves.test(n, mem, r, q, c)) return true;
        do {
            if (sp == 0) return false;
            --sp;
        } while (stack[sp].tmin > q.cull_t());
        index = stack[sp].node; tmin = stack[sp].tmin; tmax = stack[sp].tmax;
    }
}

struct Cnt { long nodes = 0, leaves = 0, tris = 0; void node() { ++nodes; } void leaf() { ++leaves; } void triangle() { ++tris; } };

int main(int argc, char** argv) {
    Scene scene = load_scene(argv[1]);
    const int W = argc > 2 ? atoi(argv[2]) : 512;
    AccelConfig cfg; cfg.kind = "kd"; cfg.threads = 1; cfg.simd = "off";
    KdStructure kd(scene.triangles, cfg);
    WideTree wt = make_wide(kd.tree);
    std::printf("kd nodes %zu wide nodes %zu\n", kd.tree.nodes.size(), wt.nodes.size());
    PinholeCamera cam(scene.camera, W, W);
    std::vector<Ray> rays;
    for (int y = 0; y < W; ++y) for (int x = 0; x < W; ++x) rays.push_back(cam.primary(x, y));
    auto mem = kd.view().memory();
    const Box3 box = kd.bounds();
    std::vector<Hit> a(rays.size()), b(rays.size());
    Cnt ca, cb;
    auto run_rec = [&](auto& cnt) { for (size_t i = 0; i < rays.size(); ++i) a[i] = closest_hit(box, rays[i], cnt, [&](const TraversalRay& r, auto& q, auto& c) { return KdRecKernel{}(kd.tree, mem, r, q, c); }); };
    auto run_br = [&](auto& cnt) { for (size_t i = 0; i < rays.size(); ++i) a[i] = closest_hit(box, rays[i], cnt, [&](const TraversalRay& r, auto& q, auto& c) { return traverse_br2(kd.tree, mem, r, q, c); }); };
    auto run_w = [&](auto& cnt) { for (size_t i = 0; i < rays.size(); ++i) b[i] = closest_hit(box, rays[i], cnt, [&](const TraversalRay& r, auto& q, auto& c) { return traverse_wide(wt, kd.tree, mem, r, q, c); }); };
    run_rec(ca); run_w(cb); { std::vector<Hit> a2 = a; Cnt cc; run_br(cc); size_t bad2 = 0; for (size_t i = 0; i < rays.size(); ++i) bad2 += !(a[i] == a2[i]); std::printf("br2 mismatches %zu\n", bad2); Cnt again; run_rec(again); }
    size_t bad = 0; for (size_t i = 0; i < rays.size(); ++i) bad += !(a[i] == b[i]);
    std::printf("mismatches %zu; per ray rec: nodes %.2f leaves %.2f tris %.2f; wide: nodes %.2f leaves %.2f tris %.2f\n", bad,
                double(ca.nodes) / rays.size(), double(ca.leaves) / rays.size(), double(ca.tris) / rays.size(),
                double(cb.nodes) / rays.size(), double(cb.leaves) / rays.size(), double(cb.tris) / rays.size());
    NoCounters nc;
    if (argc > 3) { if (argv[3][0]=='n') {} else if (argv[3][0]=='r') run_rec(nc); else if (argv[3][0]=='b') run_br(nc); else run_w(nc); return 0; }
    std::vector<double> tr, tb, tw;
    for (int rep = 0; rep < 7; ++rep) {
        auto t0 = std::chrono::steady_clock::now(); run_rec(nc);
        auto t1 = std::chrono::steady_clock::now(); run_br(nc);
        auto t2 = std::chrono::steady_clock::now(); run_w(nc);
        auto t3 = std::chrono::steady_clock::now();
        tr.push_back(std::chrono::duration<double>(t1 - t0).count()); tb.push_back(std::chrono::duration<double>(t2 - t1).count()); tw.push_back(std::chrono::duration<double>(t3 - t2).count());
    }
    std::sort(tr.begin(), tr.end()); std::sort(tb.begin(), tb.end()); std::sort(tw.begin(), tw.end());
    std::printf("ns/ray rec %.1f br2 %.1f wide %.1f  wide/rec %.3f\n", tr[3] / rays.size() * 1e9, tb[3] / rays.size() * 1e9, tw[3] / rays.size() * 1e9, tw[3] / tr[3]);
}
