// Ray sets that every acceleration structure must answer exactly as brute force does, and the
// comparison itself. One place, so that every structure faces the same edge cases:
// random rays from outside and inside the scene, axis-parallel rays with +0 and -0 components,
// rays aimed exactly at vertices, at edge points and at axis planes through vertices (where split
// planes lie), rays whose tfar ends exactly at or just before the reference hit, rays with
// tnear > 0, and invalid rays (NaN, infinite, zero or subnormal direction, tnear > tfar, tnear = +inf).
#pragma once

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/brute_force.hpp"
#include "cellrt/ray.hpp"
#include "sanitizers.hpp"

namespace cellrt::test {

// body(begin, end) over [0, n) in chunks, on every core at once: the many threads that call one
// accelerator. std::threads rather than TBB's, so that ThreadSanitizer sees how they are ordered
// (Debian's libtbb is not instrumented; docs/RELIABILITY.md). The first exception is rethrown here.
template <class Body>
void parallel_chunks(std::size_t n, std::size_t chunk, Body body) {
    std::atomic<std::size_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&] {
        try {
            for (std::size_t b; (b = next.fetch_add(chunk)) < n;) body(b, std::min(n, b + chunk));
        } catch (...) {
            std::lock_guard lock(error_mutex);
            if (!error) error = std::current_exception();
        }
    };
    std::vector<std::thread> threads;
    for (unsigned t = 1; t < std::max(1u, std::thread::hardware_concurrency()); ++t) threads.emplace_back(work);
    work();
    for (std::thread& t : threads) t.join();
    if (error) std::rethrow_exception(error);
}

struct RaySuiteOptions {
    std::size_t random = 20000;       // origins in the enlarged scene box, directions uniform
    std::size_t inside = 20000;       // origins inside the scene box
    std::size_t axis_parallel = 6000; // directions along +-x, +-y, +-z with signed zero components
    std::size_t vertices = 20000;     // aimed exactly at a vertex
    std::size_t edges = 20000;        // aimed at a point on an edge (incl. midpoints)
    std::size_t planes = 10000;       // origin on an axis plane through a vertex, or direction within it
    std::uint32_t seed = 12345;
};

class RaySuite {
public:
    RaySuite(std::span<const Triangle> tris, const RaySuiteOptions& o) : tris_(tris), rng_(o.seed) {
        for (const Triangle& t : tris) bounds_.extend(t.bounds());
        const Vec3 e = max(bounds_.extent(), Vec3(1e-3f));
        outer_ = {bounds_.lo - e * 0.5f, bounds_.hi + e * 0.5f};
        for (std::size_t i = 0; i < o.random; ++i) add(point_in(outer_), random_dir());
        for (std::size_t i = 0; i < o.inside; ++i) add(point_in(bounds_), random_dir());
        for (std::size_t i = 0; i < o.axis_parallel; ++i) add(point_in(outer_), axis_dir(i));
        for (std::size_t i = 0; i < o.vertices; ++i) aim_at(vertex());
        for (std::size_t i = 0; i < o.edges; ++i) aim_at(edge_point(i));
        for (std::size_t i = 0; i < o.planes; ++i) plane_ray(i);
        add_invalid();
    }

    const std::vector<Ray>& rays() const { return rays_; }

    // Copies of `rays` with tfar cut at the reference hit (exactly, and one ulp before) and with
    // tnear moved past it, so interval limits are checked at their edges.
    static std::vector<Ray> limited(const std::vector<Ray>& rays, const std::vector<Hit>& reference) {
        std::vector<Ray> out;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if (!reference[i].is_hit()) continue;
            Ray r = rays[i];
            r.tfar = reference[i].t;
            out.push_back(r);
            r.tfar = std::nextafter(reference[i].t, 0.f);
            out.push_back(r);
            r.tfar = kInfinity;
            r.tnear = reference[i].t;
            out.push_back(r);
            r.tnear = std::nextafter(reference[i].t, kInfinity);
            out.push_back(r);
        }
        return out;
    }

private:
    float uniform(float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng_); }
    Vec3 point_in(const Box3& b) { return {uniform(b.lo.x, b.hi.x), uniform(b.lo.y, b.hi.y), uniform(b.lo.z, b.hi.z)}; }
    Vec3 random_dir() {
        for (;;) {
            const Vec3 d{uniform(-1.f, 1.f), uniform(-1.f, 1.f), uniform(-1.f, 1.f)};
            if (dot(d, d) > 1e-4f && dot(d, d) <= 1.f) return normalize(d);
        }
    }
    Vec3 axis_dir(std::size_t i) {
        const float zero = (i / 6) % 2 ? -0.f : 0.f;
        Vec3 d(zero);
        d[(i % 6) / 2] = (i % 2) ? -1.f : 1.f;
        return d;
    }
    const Triangle& triangle() { return tris_[std::uniform_int_distribution<std::size_t>(0, tris_.size() - 1)(rng_)]; }
    Vec3 vertex() {
        const Triangle& t = triangle();
        const int k = std::uniform_int_distribution<int>(0, 2)(rng_);
        return k == 0 ? t.v0 : (k == 1 ? t.v1 : t.v2);
    }
    Vec3 edge_point(std::size_t i) {
        const Triangle& t = triangle();
        const float s = (i % 4 == 0) ? 0.5f : uniform(0.f, 1.f);
        switch (i % 3) {
            case 0: return t.v0 + (t.v1 - t.v0) * s;
            case 1: return t.v1 + (t.v2 - t.v1) * s;
            default: return t.v2 + (t.v0 - t.v2) * s;
        }
    }
    void aim_at(const Vec3& target) {
        const Vec3 org = point_in(outer_);
        const Vec3 d = target - org;
        if (dot(d, d) > 0.f) add(org, d);  // not normalised: the target lies exactly at t = 1 when representable
    }
    // Rays lying in, starting on or parallel to an axis plane through a vertex: where kd-tree
    // split planes and BIH clip planes sit.
    void plane_ray(std::size_t i) {
        const Vec3 v = vertex();
        const int axis = static_cast<int>(i % 3);
        Vec3 org = point_in(outer_);
        org[axis] = v[axis];
        Vec3 d = random_dir();
        if (i % 2) d[axis] = (i % 4 == 1) ? 0.f : -0.f;  // inside the plane
        if (dot(d, d) > 0.f) add(org, d);
    }
    void add_invalid() {
        const float nan = std::nanf("");
        const Vec3 c = bounds_.center();
        add({nan, c.y, c.z}, {1.f, 0.f, 0.f});
        add(c, {nan, 0.f, 1.f});
        add(c, {0.f, 0.f, 0.f});
        add(c, {0.f, 0.f, -1e-40f});  // subnormal
        add({kInfinity, 0.f, 0.f}, {-1.f, 0.f, 0.f});
        add(c, {kInfinity, 1.f, 0.f});
        Ray r;
        r.org = outer_.lo;
        r.dir = normalize(c - outer_.lo);
        r.tnear = 2.f;
        r.tfar = 1.f;
        rays_.push_back(r);
        r.tnear = nan;
        r.tfar = kInfinity;
        rays_.push_back(r);
        r.tnear = kInfinity;  // [inf, inf]: no distance
        rays_.push_back(r);
    }
    void add(const Vec3& org, const Vec3& dir) {
        Ray r;
        r.org = org;
        r.dir = dir;
        rays_.push_back(r);
        // Every tenth ray also starts a little way along (tnear > 0).
        if (rays_.size() % 10 == 0) {
            r.tnear = uniform(0.f, 0.5f) * length(bounds_.extent()) / std::max(length(dir), 1e-20f);
            rays_.push_back(r);
        }
    }

    std::span<const Triangle> tris_;
    std::mt19937 rng_;
    Box3 bounds_, outer_;
    std::vector<Ray> rays_;
};

inline std::string describe(const Ray& r) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "org (%a, %a, %a) dir (%a, %a, %a) tnear %a tfar %a", r.org.x, r.org.y, r.org.z,
                  r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar);
    return buf;
}

// Reference answers of brute force for a ray set, computed once (in parallel) and shared by every
// structure and traversal tested on the same scene.
struct ReferenceAnswers {
    std::vector<Ray> rays;
    std::vector<Hit> hits;
    std::vector<std::uint8_t> occluded;
};

// Brute force over all of `rays`, with the SIMD kernels of the best instruction set (held to the
// scalar loop by BruteForcePackets.SameAnswersAsTheScalarLoop). The occlusion answer is whether the
// closest hit exists: `occluded` asks whether some triangle has tnear <= t <= tfar, and the closest
// hit is one exactly when some is (docs/HIT_SEMANTICS.md). A second pass of brute force for it took
// more than half of the reference's time (Sibenik's suite: 21.8 s, 10.0 s without it, the same
// bytes); brute force's own any-hit answers are still held to these (every structure test's `brute`
// paths) and to the scalar loop's.
inline ReferenceAnswers compute_reference(std::span<const Triangle> tris, std::vector<Ray> rays) {
    AccelConfig config{"brute"};
    config.simd = "auto";
    const auto brute = make_brute_force(tris, config);
    ReferenceAnswers ref;
    ref.rays = std::move(rays);
    ref.hits.resize(ref.rays.size());
    ref.occluded.resize(ref.rays.size());
    const std::span<const Ray> all(ref.rays);
    parallel_chunks(all.size(), 256, [&](std::size_t b, std::size_t e) {
        brute->intersect(all.subspan(b, e - b), std::span(ref.hits).subspan(b, e - b));
    });
    for (std::size_t i = 0; i < ref.hits.size(); ++i) ref.occluded[i] = ref.hits[i].is_hit() ? 1 : 0;
    return ref;
}

inline constexpr std::size_t kSuiteLimitedCount = 20000;

// The first `limited_count` of RaySuite::limited(rays, hits).
inline std::vector<Ray> first_limited(const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                                      std::size_t limited_count) {
    std::vector<Ray> limited = RaySuite::limited(rays, hits);
    if (limited.size() > limited_count) limited.resize(limited_count);
    return limited;
}

// `ref`'s answers followed by those of up to `limited_count` of its rays limited at their hits.
inline ReferenceAnswers with_limited(std::span<const Triangle> tris, ReferenceAnswers ref, std::size_t limited_count) {
    ReferenceAnswers lim = compute_reference(tris, first_limited(ref.rays, ref.hits, limited_count));
    ref.rays.insert(ref.rays.end(), lim.rays.begin(), lim.rays.end());
    ref.hits.insert(ref.hits.end(), lim.hits.begin(), lim.hits.end());
    ref.occluded.insert(ref.occluded.end(), lim.occluded.begin(), lim.occluded.end());
    return ref;
}

// The suite's rays, followed by up to `limited_count` of them limited at their reference hits.
inline ReferenceAnswers reference_suite(std::span<const Triangle> tris, const RaySuiteOptions& options = {},
                                        std::size_t limited_count = kSuiteLimitedCount) {
    return with_limited(tris, compute_reference(tris, RaySuite(tris, options).rays()), limited_count);
}

// Brute force over a shared scene and the whole suite takes tens of seconds, and CTest runs every
// test in a process of its own, so reference answers are kept on disk (in the build tree) under a
// key made of the scene's triangles and the rays. A cached file is trusted only after a sample of
// its answers is recomputed and found equal, so a changed triangle kernel cannot leave stale answers.
namespace detail {

inline std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h = 1469598103934665603ull) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

inline bool read_reference(const std::string& path, std::size_t rays, ReferenceAnswers& out) {
    std::ifstream in(path, std::ios::binary);
    std::uint64_t n = 0;
    if (!in.read(reinterpret_cast<char*>(&n), sizeof n) || n != rays) return false;
    out.rays.resize(n);
    out.hits.resize(n);
    out.occluded.resize(n);
    in.read(reinterpret_cast<char*>(out.rays.data()), static_cast<std::streamsize>(n * sizeof(Ray)));
    in.read(reinterpret_cast<char*>(out.hits.data()), static_cast<std::streamsize>(n * sizeof(Hit)));
    in.read(reinterpret_cast<char*>(out.occluded.data()), static_cast<std::streamsize>(n));
    return static_cast<bool>(in);
}

inline void write_reference(const std::string& path, const ReferenceAnswers& ref) {
    const std::string temp = path + ".part" + std::to_string(::getpid());
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        const std::uint64_t n = ref.rays.size();
        out.write(reinterpret_cast<const char*>(&n), sizeof n);
        out.write(reinterpret_cast<const char*>(ref.rays.data()), static_cast<std::streamsize>(n * sizeof(Ray)));
        out.write(reinterpret_cast<const char*>(ref.hits.data()), static_cast<std::streamsize>(n * sizeof(Hit)));
        out.write(reinterpret_cast<const char*>(ref.occluded.data()), static_cast<std::streamsize>(n));
    }
    std::filesystem::rename(temp, path);
}

// Recomputes every 97th answer of `ref` with brute force.
inline bool sample_agrees(std::span<const Triangle> tris, const ReferenceAnswers& ref) {
    std::vector<Ray> sample;
    std::vector<std::size_t> at;
    for (std::size_t i = 0; i < ref.rays.size(); i += 97) sample.push_back(ref.rays[i]), at.push_back(i);
    const ReferenceAnswers check = compute_reference(tris, sample);
    for (std::size_t k = 0; k < at.size(); ++k)
        if (!(check.hits[k] == ref.hits[at[k]]) || check.occluded[k] != ref.occluded[at[k]]) return false;
    return true;
}

}  // namespace detail

// The folder of the cached answers: this build tree's, or the one CELLRT_TEST_CACHE names, which
// tools/test.sh points at the Release build's for the sanitizer runs: brute force over a shared scene
// is minutes under AddressSanitizer, and a sample of every file is still recomputed there.
inline std::string reference_cache_dir() {
    if (const char* env = std::getenv("CELLRT_TEST_CACHE")) return env;
    return CELLRT_TEST_CACHE;
}

// Where stored_answers() keeps the answers that start from `rays` on `tris`.
inline std::string stored_answers_path(std::span<const Triangle> tris, std::span<const Ray> rays) {
    const std::uint64_t h = detail::fnv1a(rays.data(), rays.size_bytes(), detail::fnv1a(tris.data(), tris.size_bytes()));
    const std::string dir = reference_cache_dir();
    std::filesystem::create_directories(dir);
    char name[32];
    std::snprintf(name, sizeof name, "%016llx", static_cast<unsigned long long>(h));
    return dir + "/" + name + ".ref";
}

// The answers `compute` gives, kept on disk under a key made of the triangles and `rays` (the rays
// the answers start from): one process computes, those that need the same answers wait for its file.
// A cached file is used only if `consistent` accepts it: the key holds the rays the answers start
// from, not the rays derived from them (the limited copies), which the test code may have changed.
template <class Compute, class Consistent>
ReferenceAnswers stored_answers(std::span<const Triangle> tris, std::span<const Ray> rays, Compute compute,
                                Consistent consistent) {
    const std::string path = stored_answers_path(tris, rays);
    const int lock_fd = ::open((path + ".lock").c_str(), O_CREAT | O_RDWR, 0644);
    if (lock_fd >= 0) ::flock(lock_fd, LOCK_EX);
    ReferenceAnswers ref;
    std::size_t expected = 0;
    {
        std::ifstream in(path, std::ios::binary);
        std::uint64_t n = 0;
        if (in.read(reinterpret_cast<char*>(&n), sizeof n)) expected = n;
    }
    if (expected == 0 || !detail::read_reference(path, expected, ref) || !consistent(ref) ||
        !detail::sample_agrees(tris, ref)) {
        ref = compute();
        detail::write_reference(path, ref);
    }
    if (lock_fd >= 0) {
        ::flock(lock_fd, LOCK_UN);
        ::close(lock_fd);
    }
    return ref;
}

// compute_reference() of `rays`, kept on disk: the tests of every structure on one scene's frame share it.
inline ReferenceAnswers stored_reference(std::span<const Triangle> tris, const std::vector<Ray>& rays) {
    return stored_answers(
        tris, rays, [&] { return compute_reference(tris, rays); },
        [&](const ReferenceAnswers& ref) {
            return ref.rays.size() == rays.size() &&
                   std::memcmp(ref.rays.data(), rays.data(), rays.size() * sizeof(Ray)) == 0;
        });
}

// reference_suite() of `tris`, kept on disk: the tests of every structure on the same triangles share it.
inline ReferenceAnswers stored_suite(std::span<const Triangle> tris, const RaySuiteOptions& options = {}) {
    const std::vector<Ray> rays = RaySuite(tris, options).rays();
    return stored_answers(
        tris, rays, [&] { return reference_suite(tris, options); },
        [&](const ReferenceAnswers& ref) {
            const std::size_t n = rays.size();
            if (ref.rays.size() < n || std::memcmp(ref.rays.data(), rays.data(), n * sizeof(Ray)) != 0) return false;
            const std::vector<Ray> limited =
                first_limited(rays, std::vector<Hit>(ref.hits.begin(), ref.hits.begin() + n), kSuiteLimitedCount);
            // memcmp of an empty vector's data() (null) is undefined, which UBSan reports: a suite
            // may limit no ray (the soup beside triangles at +-3e38 limits none).
            return ref.rays.size() - n == limited.size() &&
                   (limited.empty() ||
                    std::memcmp(ref.rays.data() + n, limited.data(), limited.size() * sizeof(Ray)) == 0);
        });
}

// reference_suite() of a triangle set, computed once and shared by every structure and traversal
// tested on it: in memory within a process, on disk across processes.
inline const ReferenceAnswers& cached_reference(const std::string& key, std::span<const Triangle> tris) {
    static std::mutex mutex;
    static std::map<std::string, std::unique_ptr<ReferenceAnswers>> cache;
    std::lock_guard lock(mutex);
    auto& slot = cache[key];
    if (!slot) slot = std::make_unique<ReferenceAnswers>(stored_suite(tris));
    return *slot;
}

// The rays a sanitized test program traces of a suite (docs/RELIABILITY.md): every thirteenth, and
// every invalid one (a few rays, each a case of its own). The sanitizers look for memory errors, races
// and undefined behaviour on the kernels' paths, which a thirteenth of the suite still takes, at a
// thirteenth of a cost 5 to 10 times the Release build's; the Release stage checks every answer.
// Thirteen is prime to the periods the suite's rays repeat with (a tnear > 0 copy at every tenth
// index; axis-parallel directions 12, edge points 4 and 3, axis planes 4 and 3, interval limits 4),
// so the sample keeps each kind: with five, every axis-parallel ray along y would fall out.
inline constexpr std::size_t kSanitizedSampleStride = 13;
inline constexpr std::size_t kSanitizedStride = kSanitizers.empty() ? 1 : kSanitizedSampleStride;

// The rays every kernel must answer as misses (cellrt::is_valid, cellrt/ray.hpp).
inline bool is_invalid(const Ray& r) { return !is_valid(r); }

inline bool in_sanitized_sample(std::size_t i, const Ray& r, std::size_t stride = kSanitizedStride) {
    return i % stride == 0 || is_invalid(r);
}

inline std::vector<Ray> sanitized_sample(const std::vector<Ray>& rays, std::size_t stride = kSanitizedStride) {
    std::vector<Ray> out;
    for (std::size_t i = 0; i < rays.size(); ++i)
        if (in_sanitized_sample(i, rays[i], stride)) out.push_back(rays[i]);
    return out;
}

inline ReferenceAnswers sanitized_sample(const ReferenceAnswers& ref, std::size_t stride = kSanitizedStride) {
    ReferenceAnswers out;
    for (std::size_t i = 0; i < ref.rays.size(); ++i) {
        if (!in_sanitized_sample(i, ref.rays[i], stride)) continue;
        out.rays.push_back(ref.rays[i]);
        out.hits.push_back(ref.hits[i]);
        out.occluded.push_back(ref.occluded[i]);
    }
    return out;
}

namespace detail {

inline std::size_t expect_all_match(const Accelerator& tested, const ReferenceAnswers& ref, const std::string& what) {
    std::vector<Hit> got(ref.rays.size());
    std::vector<std::uint8_t> got_occ(ref.rays.size());
    const std::span<const Ray> all(ref.rays);
    parallel_chunks(all.size(), 256, [&](std::size_t b, std::size_t e) {
        tested.intersect(all.subspan(b, e - b), std::span(got).subspan(b, e - b));
        tested.occluded(all.subspan(b, e - b), std::span(got_occ).subspan(b, e - b));
    });
    std::size_t bad = 0;
    for (std::size_t i = 0; i < ref.rays.size(); ++i) {
        if (got[i] == ref.hits[i] && got_occ[i] == ref.occluded[i]) continue;
        if (++bad <= 5)
            ADD_FAILURE() << what << ": ray " << i << " " << describe(ref.rays[i]) << "\n  closest: got prim "
                          << got[i].prim << " t " << got[i].t << ", want prim " << ref.hits[i].prim << " t "
                          << ref.hits[i].t << "\n  occluded: got " << int(got_occ[i]) << ", want "
                          << int(ref.occluded[i]);
    }
    EXPECT_EQ(bad, 0u) << what << ": " << bad << " of " << ref.rays.size() << " rays differ from brute force";
    return bad;
}

}  // namespace detail

// Compares closest hits (t, triangle, barycentrics) and any-hit answers of `tested` with the
// reference (under the sanitizers, on sanitized_sample() of it); reports the first few differences
// in full. Returns the number of differing rays.
inline std::size_t expect_matches(const Accelerator& tested, const ReferenceAnswers& ref, const std::string& what) {
    if (kSanitizedStride == 1) return detail::expect_all_match(tested, ref, what);
    return detail::expect_all_match(tested, sanitized_sample(ref), what);
}

}  // namespace cellrt::test
