// Instruction-level profiling (docs/PROFILE.md): the kernels' per-ray work counters against trees
// traced by hand, callgrind's totals against a loop whose instructions and branches are known, the
// hardware counters (or their clean absence), and `cellrt profile` end to end.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>
#include <vector>

#include "bih/bih_traversal.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "kdtree/kd_traversal.hpp"
#include "simd/isa.hpp"
#include "profile/callgrind.hpp"
#include "profile/frame_profile.hpp"
#include "profile/hardware_counters.hpp"
#include "profile/measured_accelerator.hpp"
#include "sanitizers.hpp"

namespace cellrt {
namespace {

// ---------------------------------------------------------------------------------------------------
// Per-ray work counters on hand-built trees.
//
// Four triangles, each in a plane x = c (c = 0.5, 1.5, 2.5, 3.5) covering y + z <= 1 of the unit
// square; the scene box is [0,4] x [0,1] x [0,1]. Both trees split at x = 2 and then the left half at
// x = 1 (BIH: clip planes at the triangles' own x), giving leaves {0}, {1} and {2, 3}:
//
//   kd:  0: x < 2 ? 2 : 3      2: x < 1 ? 4 : 5      3: leaf {2, 3}   4: leaf {0}   5: leaf {1}
//   BIH: 0: left <= 1.5, right >= 2.5 -> 2, 3     2: left <= 0.5, right >= 1.5 -> 4, 5    (leaves as kd)
//
// Node 1 is the padding leaf both layouts reserve.

std::vector<Triangle> slab_triangles() {
    std::vector<Triangle> t;
    for (float c : {0.5f, 1.5f, 2.5f, 3.5f}) t.push_back({{c, 0.f, 0.f}, {c, 1.f, 0.f}, {c, 0.f, 1.f}});
    return t;
}

Box3 slab_bounds() { return {{0.f, 0.f, 0.f}, {4.f, 1.f, 1.f}}; }

detail::KdTree hand_kdtree() {
    using detail::KdNode;
    detail::KdTree tree;
    tree.nodes = {KdNode::inner(0, 2.f, 2), KdNode::leaf(0, 0), KdNode::inner(0, 1.f, 4),
                  KdNode::leaf(2, 2),       KdNode::leaf(0, 1), KdNode::leaf(1, 1)};
    tree.indices = {0, 1, 2, 3};
    tree.bounds = slab_bounds();
    tree.triangle_count = 4;
    return tree;
}

detail::BihTree hand_bih() {
    using detail::BihNode;
    detail::BihTree tree;
    tree.nodes = {BihNode::inner(0, 1.5f, 2.5f, 2), BihNode::leaf(0, 0), BihNode::inner(0, 0.5f, 1.5f, 4),
                  BihNode::leaf(2, 2),              BihNode::leaf(0, 1), BihNode::leaf(1, 1)};
    tree.triangles = slab_triangles();
    tree.prims = {0, 1, 2, 3};
    tree.bounds = slab_bounds();
    return tree;
}

struct Work {
    std::uint64_t nodes, leaves, triangles;
};

// One ray, its answers and the work traced by hand for each query (closest hit, any hit).
struct HandCase {
    const char* what;
    Ray ray;
    std::uint32_t closest;  // kNoHit for a miss
    float t;
    Work kd_closest, kd_any, bih_closest, bih_any;
};

Ray ray(Vec3 org, Vec3 dir) { return {org, 0.f, dir, kInfinity}; }

// Traced on paper (the comments name the nodes in visiting order; "pop n: culled" is a stack entry that
// starts beyond the best hit).
const HandCase kHandCases[] = {
    // kd/BIH: 0 (push 3), 2 (push 5), leaf 4 hits 0 at t = 1.5; pop 5, 3: culled.
    {"+x at the first triangle", ray({-1.f, .25f, .25f}, {1.f, 0.f, 0.f}), 0, 1.5f, {2, 1, 1}, {2, 1, 1}, {2, 1, 1},
     {2, 1, 1}},
    // Passes beside every triangle (y + z = 1.5): every leaf, every triangle.
    {"+x beside all triangles", ray({-1.f, .75f, .75f}, {1.f, 0.f, 0.f}), kNoHit, 0.f, {2, 3, 4}, {2, 3, 4},
     {2, 3, 4}, {2, 3, 4}},
    // Negative direction: 0 (near child 3, push 2), leaf 3 tests 2 then 3 (closest: t = 1.5); pop 2: culled.
    // Any hit stops at triangle 2.
    {"-x from beyond the last triangle", ray({5.f, .25f, .25f}, {-1.f, 0.f, 0.f}), 3, 1.5f, {1, 1, 2}, {1, 1, 1},
     {1, 1, 2}, {1, 1, 1}},
    // Starts inside at x = 1.2: 0 (push 3), 2 whose near child 4 lies behind the origin: far child 5, hit
    // 1 at t = 0.3; pop 3: culled.
    {"+x from between triangles 0 and 1", ray({1.2f, .25f, .25f}, {1.f, 0.f, 0.f}), 1, .3f, {2, 1, 1}, {2, 1, 1},
     {2, 1, 1}, {2, 1, 1}},
    // Along +y in the plane x = 2. kd: the root's plane distance is 0 * inf = NaN, so both children:
    // 2 (whose plane x = 1 is behind: child 5 only), leaf 5, then leaf 3; no triangle faces the ray.
    // BIH: x = 2 lies in the root's gap between 1.5 and 2.5: one node, nothing else.
    {"+y in the plane x = 2", ray({2.f, -1.f, .25f}, {0.f, 1.f, 0.f}), kNoHit, 0.f, {2, 2, 3}, {2, 2, 3},
     {1, 0, 0}, {1, 0, 0}},
    // Misses the scene box: no node at all.
    {"+x above the box", ray({-1.f, 2.f, .5f}, {1.f, 0.f, 0.f}), kNoHit, 0.f, {0, 0, 0}, {0, 0, 0}, {0, 0, 0},
     {0, 0, 0}},
};

void expect_work(const TraversalCounters& c, const Work& w, const std::string& where) {
    EXPECT_EQ(c.rays, 1u) << where;
    EXPECT_EQ(c.nodes, w.nodes) << where << ": nodes";
    EXPECT_EQ(c.leaves, w.leaves) << where << ": leaves";
    EXPECT_EQ(c.triangles, w.triangles) << where << ": triangles";
}

// Runs `kernel` (a with_*_kernel function object over `tree`) on every hand case, both queries.
template <class Tree, class Memory, class Kernel>
void check_hand_cases(const Tree& tree, Memory mem, Kernel kernel, bool bih, const std::string& name) {
    for (const HandCase& h : kHandCases) {
        const std::string where = name + ", " + h.what;
        auto run = [&](const detail::TraversalRay& r, auto& q, auto& c) { return kernel(tree, mem, r, q, c); };
        TraversalCounters closest, any;
        Hit hit;
        std::uint8_t occluded = 2;
        detail::closest_hits(tree.bounds, std::span(&h.ray, 1), std::span(&hit, 1), &closest, run);
        detail::any_hits(tree.bounds, std::span(&h.ray, 1), std::span(&occluded, 1), &any, run);
        EXPECT_EQ(hit.prim, h.closest) << where;
        if (h.closest != kNoHit) {
            EXPECT_FLOAT_EQ(hit.t, h.t) << where;
        }
        EXPECT_EQ(occluded, h.closest != kNoHit ? 1 : 0) << where;
        expect_work(closest, bih ? h.bih_closest : h.kd_closest, where + ", closest hit");
        expect_work(any, bih ? h.bih_any : h.kd_any, where + ", any hit");
    }
}

TEST(ProfileWorkCounters, KdKernelsCountExactlyTheHandTracedWork) {
    const std::vector<Triangle> tris = slab_triangles();
    const detail::KdTree tree = hand_kdtree();
    const detail::DirectMemory<detail::KdNode> mem{tree.nodes.data(), tree.indices.data(), tris.data()};
    for (auto [t, name] : {std::pair{detail::KdTraversal::rec, "kd rec"},
                           {detail::KdTraversal::branched, "kd branched"},
                           {detail::KdTraversal::branchless, "kd branchless"}})
        detail::with_kd_kernel(t, [&](auto kernel) { check_hand_cases(tree, mem, kernel, false, name); });
}

TEST(ProfileWorkCounters, BihKernelsCountExactlyTheHandTracedWork) {
    const detail::BihTree tree = hand_bih();
    const detail::DirectMemory<detail::BihNode> mem{tree.nodes.data(), tree.prims.data(), tree.triangles.data()};
    for (auto [t, name] : {std::pair{detail::BihTraversal::branched, "bih branched"},
                           {detail::BihTraversal::branchless, "bih branchless"}})
        detail::with_bih_kernel(t, [&](auto kernel) { check_hand_cases(tree, mem, kernel, true, name); });
}

TEST(ProfileWorkCounters, BatchesSumTheirRaysWork) {
    const std::vector<Triangle> tris = slab_triangles();
    const detail::KdTree tree = hand_kdtree();
    const detail::DirectMemory<detail::KdNode> mem{tree.nodes.data(), tree.indices.data(), tris.data()};
    std::vector<Ray> rays;
    Work sum{0, 0, 0};
    for (const HandCase& h : kHandCases) {
        rays.push_back(h.ray);
        sum = {sum.nodes + h.kd_closest.nodes, sum.leaves + h.kd_closest.leaves,
               sum.triangles + h.kd_closest.triangles};
    }
    rays.push_back(ray({0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}));  // invalid: counted as a ray, never traversed
    std::vector<Hit> hits(rays.size());
    TraversalCounters c;
    detail::closest_hits(tree.bounds, rays, hits, &c, [&](const detail::TraversalRay& r, auto& q, auto& k) {
        return detail::traverse_branched<detail::KdTraits>(tree, mem, r, q, k);
    });
    EXPECT_EQ(c.rays, rays.size());
    EXPECT_EQ(c.nodes, sum.nodes);
    EXPECT_EQ(c.leaves, sum.leaves);
    EXPECT_EQ(c.triangles, sum.triangles);
}

// ---------------------------------------------------------------------------------------------------
// A loop whose cost is known exactly: 8 instructions per iteration on either path and two conditional
// branches, one on the data (taken on a 0 byte) and the loop's own. x86-64 assembly, so that no
// compiler can change the count.

constexpr std::size_t kLoopIterations = 100000;

#if defined(__x86_64__)
constexpr bool kHaveBranchLoop = true;

[[gnu::always_inline]] inline std::uint64_t branch_loop(const std::uint8_t* bits, std::size_t n) {
    std::uint64_t sum = 0;
    asm volatile(
        "1:\n\t"
        "movzbl (%[p]), %%eax\n\t"
        "inc %[p]\n\t"
        "test %%eax, %%eax\n\t"
        "jz 2f\n\t"
        "add $1, %[s]\n\t"
        "jmp 3f\n"
        "2:\n\t"
        "sub $1, %[s]\n\t"
        "nop\n"
        "3:\n\t"
        "dec %[n]\n\t"
        "jnz 1b\n\t"
        : [p] "+r"(bits), [n] "+r"(n), [s] "+r"(sum)
        :
        : "eax", "cc", "memory");
    return sum;
}
#else
constexpr bool kHaveBranchLoop = false;
inline std::uint64_t branch_loop(const std::uint8_t*, std::size_t) { return 0; }
#endif

// The two measured regions (callgrind toggles on their names): a fixed pseudo-random bit sequence,
// which no predictor can learn, and all zeros, which every predictor learns at once. Two functions,
// never folded into one (no_icf), so that each has its own name.
[[gnu::noinline, gnu::no_icf]] std::uint64_t random_branches(const std::vector<std::uint8_t>& bits) {
    return branch_loop(bits.data(), bits.size());
}
[[gnu::noinline, gnu::no_icf]] std::uint64_t steady_branches(const std::vector<std::uint8_t>& bits) {
    return branch_loop(bits.data(), bits.size());
}

std::vector<std::uint8_t> random_bits() {
    std::vector<std::uint8_t> bits(kLoopIterations);
    std::uint32_t x = 0x2545f491u;  // xorshift32 (Marsaglia 2003)
    for (auto& b : bits) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        b = static_cast<std::uint8_t>(x >> 31);
    }
    return bits;
}

// What callgrind runs: both regions, once each.
TEST(ProfileSyntheticChild, DISABLED_BranchLoops) {
    const std::vector<std::uint8_t> random = random_bits(), steady(kLoopIterations, 0);
    EXPECT_NE(random_branches(random), 0u);
    EXPECT_NE(steady_branches(steady), 0u);
}

std::vector<std::string> branch_loops_command() {
    return {std::filesystem::read_symlink("/proc/self/exe").string(), "--gtest_also_run_disabled_tests",
            "--gtest_filter=ProfileSyntheticChild.DISABLED_BranchLoops"};
}

// Tolerances: the loop's instructions are exact; what surrounds it (call, return, two loads of the
// vector's bounds) is under 40 instructions. Callgrind's predictor (2-bit counters over 7 history bits)
// cannot learn the random sequence, so it misses half of the data branches, within 2 % of the
// iterations (the binomial spread is 0.16 %); on steady data it misses only while it warms up.
TEST(ProfileCallgrind, CountsAKnownLoopExactlyAndItsMispredictions) {
    if (!kHaveBranchLoop) GTEST_SKIP() << "the synthetic loop is x86-64 assembly";
    if (profile::find_valgrind().empty()) GTEST_SKIP() << "valgrind not found on PATH";
    CELLRT_SKIP_UNDER_SANITIZERS("valgrind cannot run this sanitized test program");
    const double n = kLoopIterations;
    profile::CallgrindOptions random_opts, steady_opts;
    random_opts.toggle_collect = {"*random_branches*"};
    steady_opts.toggle_collect = {"*steady_branches*"};
    const profile::EventCounts random = profile::run_callgrind(branch_loops_command(), random_opts);
    const profile::EventCounts steady = profile::run_callgrind(branch_loops_command(), steady_opts);

    for (const auto* c : {&random, &steady}) {
        EXPECT_GE(c->instructions, 8 * kLoopIterations);
        EXPECT_LE(c->instructions, 8 * kLoopIterations + 40);
        EXPECT_GE(c->branches, 2 * kLoopIterations);  // callgrind: conditional (and indirect) branches only
        EXPECT_LE(c->branches, 2 * kLoopIterations + 4);
        EXPECT_FALSE(c->cycles.has_value());
    }
    EXPECT_EQ(random.instructions, steady.instructions) << "the same code on other data";
    EXPECT_NEAR(static_cast<double>(random.mispredictions), 0.5 * n, 0.02 * n);
    EXPECT_LE(static_cast<double>(steady.mispredictions), 0.001 * n);
}

TEST(ProfileCallgrind, AFailedRunIsAnErrorThatShowsTheProgramsOutput) {
    if (profile::find_valgrind().empty()) GTEST_SKIP() << "valgrind not found on PATH";
    try {
        profile::run_callgrind({"/bin/sh", "-c", "echo boom >&2; exit 3"}, {});
        ADD_FAILURE() << "a failed run returned counts";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("exit status 3"), std::string::npos) << m;
        EXPECT_NE(m.find("boom"), std::string::npos) << m;
    }
}

TEST(ProfileCallgrind, ParsesTotalsAndNamesTheLineAtFault) {
    std::istringstream out("# callgrind format\nevents: Ir Bc Bcm Bi Bim\nsummary: 900 80 7\n"
                           "fn=(1) main\n3 900 80 7\ntotals: 1000 100 9 4 1\n");
    const profile::EventCounts c = profile::parse_callgrind_totals(out, "cg.out");
    EXPECT_EQ(c.instructions, 1000u);
    EXPECT_EQ(c.branches, 104u);
    EXPECT_EQ(c.mispredictions, 10u);
    EXPECT_FALSE(c.cycles.has_value());

    std::istringstream summary_only("events: Ir Bc Bcm Bi Bim\nsummary: 50 6 2\n");  // trailing zeros left off
    const profile::EventCounts s = profile::parse_callgrind_totals(summary_only, "cg.out");
    EXPECT_EQ(s.instructions, 50u);
    EXPECT_EQ(s.branches, 6u);
    EXPECT_EQ(s.mispredictions, 2u);

    auto message = [](const std::string& text) {
        std::istringstream in(text);
        try {
            profile::parse_callgrind_totals(in, "cg.out");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message("events: Ir Bc Bcm Bi Bim\ntotals: 10 x2\n").find("cg.out:2"), std::string::npos);
    EXPECT_NE(message("events: Ir\ntotals: 10\n").find("--branch-sim=yes"), std::string::npos);
    EXPECT_NE(message("events: Ir Bc Bcm Bi Bim\n").find("no 'totals:'"), std::string::npos);
    EXPECT_NE(message("events: Ir Bc\ntotals: 1 2 3\n").find("cg.out:2"), std::string::npos);
}

// The callgrind route names the SIMD set the child must use: what "auto" means here, except AVX-512,
// which valgrind cannot run.
TEST(ProfileCallgrind, NamesTheSimdSetTheChildRuns) {
    std::string note;
    AccelConfig off{.kind = "kd", .traversal = "rec", .simd = "off"};
    EXPECT_EQ(profile::config_for_callgrind(off, note).simd, "off");
    EXPECT_EQ(profile::config_for_callgrind({.kind = "kd", .simd = "portable"}, note).simd, "portable");
    EXPECT_TRUE(note.empty());
    const detail::Isa best = detail::available_isas().back();
    const AccelConfig resolved = profile::config_for_callgrind({.kind = "bih", .simd = "auto"}, note);
    if (best == detail::Isa::avx512) {
        EXPECT_EQ(resolved.simd, "avx2");
        EXPECT_NE(note.find("AVX-512"), std::string::npos);
        try {
            profile::config_for_callgrind({.kind = "bih", .simd = "avx512"}, note);
            ADD_FAILURE() << "valgrind was given AVX-512 code";
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()), "SIMD instruction set avx512: valgrind cannot run AVX-512 code; profile "
                                             "it with hardware counters, or choose avx2");
        }
    } else {
        EXPECT_EQ(resolved.simd, detail::to_string(best));
        EXPECT_TRUE(note.empty());
    }
}

// ---------------------------------------------------------------------------------------------------
// Hardware counters: where the machine has them, they count the known loop; where it has none (most
// virtual machines), every entry point says so in the same one line.

TEST(ProfileHardware, CountsTheKnownLoopOrSaysInOneLineWhyNot) {
    std::string why;
    auto counters = profile::HardwareCounters::open(profile::HardwareCounters::Threads::calling, why);
    if (!counters) {
        EXPECT_EQ(why.rfind("hardware counters unavailable: perf_event_open(", 0), 0u) << why;
        EXPECT_EQ(why.find('\n'), std::string::npos) << why;
        try {
            profile::HardwareCounters::open_or_throw(profile::HardwareCounters::Threads::calling_and_new);
            ADD_FAILURE() << "open_or_throw succeeded where open failed";
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()), why);
        }
        const Scene scene = make_builtin_scene("builtin:spheres?tris=200");
        const auto accel = make_accelerator(scene.triangles, {.kind = "kd"});
        const profile::MeasuredAccelerator measured(*accel, profile::MeasuredAccelerator::Counting::hardware);
        const Ray r = ray(scene.camera.position, scene.camera.look_at - scene.camera.position);
        Hit hit;
        try {
            measured.intersect(std::span(&r, 1), std::span(&hit, 1), nullptr);
            ADD_FAILURE() << "a measured accelerator counted without counters";
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()), why);
        }
        return;
    }
    if (!kHaveBranchLoop) GTEST_SKIP() << "the synthetic loop is x86-64 assembly";
    // Around the loop: the call, the counters' own ioctl wrappers; well under 500 instructions.
    const double n = kLoopIterations;
    const std::vector<std::uint8_t> random = random_bits(), steady(kLoopIterations, 0);
    counters->count([&] { random_branches(random); });
    const profile::EventCounts r = counters->read();
    auto fresh = profile::HardwareCounters::open_or_throw(profile::HardwareCounters::Threads::calling);
    fresh.count([&] { steady_branches(steady); });
    const profile::EventCounts s = fresh.read();
    for (const auto* c : {&r, &s}) {
        EXPECT_GE(c->instructions, 8 * kLoopIterations);
        EXPECT_LE(c->instructions, 8 * kLoopIterations + 500);
        EXPECT_GE(c->branches, 2 * kLoopIterations);      // every branch: the jumps too
        EXPECT_LE(c->branches, 3 * kLoopIterations + 500);
        ASSERT_TRUE(c->cycles.has_value());
        EXPECT_GT(*c->cycles, 0u);
    }
    EXPECT_NEAR(static_cast<double>(r.mispredictions), 0.5 * n, 0.15 * n);
    EXPECT_LE(static_cast<double>(s.mispredictions), 0.01 * n + 500);
    EXPECT_GT(*r.cycles, *s.cycles) << "mispredictions cost cycles";
}

// ---------------------------------------------------------------------------------------------------
// `cellrt profile` end to end on a small built-in scene.

struct ShellResult {
    int status;
    std::string output;  // stdout and stderr
};

ShellResult run_shell(const std::string& command) {
    ShellResult r{-1, {}};
    FILE* p = ::popen((command + " 2>&1").c_str(), "r");
    if (!p) return r;
    char buf[4096];
    for (std::size_t k; (k = std::fread(buf, 1, sizeof buf, p)) > 0;) r.output.append(buf, k);
    r.status = ::pclose(p);
    return r;
}

TEST(ProfileCli, ReportsBothRegionsAndTheKernelsWork) {
    std::string why;
    const bool hardware =
        profile::HardwareCounters::open(profile::HardwareCounters::Threads::calling_and_new, why).has_value();
    if (!hardware && profile::find_valgrind().empty()) GTEST_SKIP() << why << "; and valgrind not found on PATH";
    if (!hardware) CELLRT_SKIP_UNDER_SANITIZERS(why << "; and valgrind cannot run the sanitized cellrt program");
    const std::string spec = "builtin:spheres?tris=300";
    const auto dir = std::filesystem::temp_directory_path() / ("cellrt_profile_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string json = (dir / "p.json").string();
    const ShellResult run = run_shell(std::string(CELLRT_CLI) + " profile '" + spec +
                              "' --accel bih --traversal branchless --size 24x16 --packet 8 --json " + json);
    ASSERT_EQ(run.status, 0) << run.output;
    if (!hardware) {
        // The one line that says why, then the software route.
        EXPECT_NE(run.output.find(why + "; falling back to callgrind"), std::string::npos) << run.output;
        EXPECT_NE(run.output.find("n/a"), std::string::npos) << run.output;
    }
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    std::filesystem::remove_all(dir);

    EXPECT_EQ(j["method"], hardware ? "hardware" : "callgrind");
    EXPECT_EQ(j["accel"], "bih");
    EXPECT_EQ(j["traversal"], "branchless");
    EXPECT_EQ(j["width"], 24);
    EXPECT_EQ(j["height"], 16);
    // The same frame rendered here, single-threaded, gives the kernels' work the report shows.
    const Scene scene = make_builtin_scene(spec);
    const auto accel = make_accelerator(scene.triangles, {.kind = "bih", .traversal = "branchless"});
    RenderOptions o;
    o.width = 24;
    o.height = 16;
    o.threads = 1;
    o.packet = 8;
    o.count = true;
    RenderStats st;
    render(scene, *accel, o, &st);
    EXPECT_EQ(j["rays"]["primary"], 24u * 16u);
    EXPECT_EQ(j["rays"]["shadow"], st.secondary_rays);
    EXPECT_EQ(j["work"]["nodes"], st.primary.nodes + st.secondary.nodes);
    EXPECT_EQ(j["work"]["leaves"], st.primary.leaves + st.secondary.leaves);
    EXPECT_EQ(j["work"]["triangles"], st.primary.triangles + st.secondary.triangles);
    // The traversal is part of the render, and costs something.
    const auto& whole = j["regions"]["render"];
    const auto& trav = j["regions"]["traversal"];
    EXPECT_GT(trav["instructions"].get<std::uint64_t>(), 0u);
    EXPECT_LT(trav["instructions"].get<std::uint64_t>(), whole["instructions"].get<std::uint64_t>());
    EXPECT_LE(trav["branches"].get<std::uint64_t>(), whole["branches"].get<std::uint64_t>());
    EXPECT_LE(trav["mispredictions"].get<std::uint64_t>(), whole["mispredictions"].get<std::uint64_t>());
    EXPECT_EQ(whole["cycles"].is_null(), !hardware);
    EXPECT_EQ(trav["cpi"].is_null(), !hardware);
}

TEST(ProfileCli, RefusesHardwareCountingWithoutCounters) {
    std::string why;
    if (profile::HardwareCounters::open(profile::HardwareCounters::Threads::calling_and_new, why))
        GTEST_SKIP() << "this machine has hardware counters";
    const ShellResult run =
        run_shell(std::string(CELLRT_CLI) + " profile 'builtin:spheres?tris=100' --size 4x4 --method hardware");
    EXPECT_NE(run.status, 0);
    EXPECT_EQ(run.output, "cellrt: error: " + why + "\n");
}

}  // namespace
}  // namespace cellrt
