// What the fuzz targets share: the scratch files the loaders read (they take paths), the checks of
// what a parser accepted, and the agreement of every structure with brute force on a small scene.
// A failed check calls abort(), which libFuzzer reports as a crash and saves the input for.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "cellrt/scene.hpp"
#include "simd/isa.hpp"

namespace cellrt::fuzz {

[[noreturn]] inline void fail(const std::string& what) {
    std::fprintf(stderr, "cellrt fuzz check failed: %s\n", what.c_str());
    std::abort();
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

// The parser's result, or nullopt where it refused the input with a cellrt::Error, the one way a
// parser may refuse. Any other exception escapes to libFuzzer, which reports it as a crash. Where
// `prefix` is given, the message must start with it (the loaders' messages name the file first, the
// specs' the spec), as far as a message can hold it: what() ends at a NUL byte.
template <class Parse>
auto parse_or_refuse(Parse&& parse, std::string_view prefix = {}) -> std::optional<decltype(parse())> {
    try {
        return parse();
    } catch (const Error& e) {
        const std::string_view message = e.what();
        const std::string_view readable = prefix.substr(0, prefix.find('\0'));
        if (message.substr(0, readable.size()) != readable || (message.empty() && readable.size() == prefix.size()))
            fail("a refusal without a message naming '" + std::string(prefix) + "': " + std::string(message));
        return std::nullopt;
    }
}

// The values of the runs of decimal digits in `text`, in order, a value beyond 64 bits as the
// largest: what a grammar of numbers must have read, whatever it allows around them.
inline std::vector<std::uint64_t> digit_runs(std::string_view text) {
    std::vector<std::uint64_t> runs;
    for (std::size_t i = 0; i < text.size();) {
        if (text[i] < '0' || text[i] > '9') {
            ++i;
            continue;
        }
        std::uint64_t v = 0;
        for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i) {
            const std::uint64_t digit = static_cast<std::uint64_t>(text[i] - '0');
            constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
            v = v > (kMax - digit) / 10 ? kMax : v * 10 + digit;
        }
        runs.push_back(v);
    }
    return runs;
}

// A folder of this process's own for the files the loaders read, removed when the process exits
// normally (after a crash it stays, with the input libFuzzer also saved).
class ScratchDir {
public:
    static const std::filesystem::path& path() {
        static const ScratchDir dir;
        return dir.path_;
    }

private:
    ScratchDir() {
        std::string templ = (std::filesystem::temp_directory_path() / "cellrt-fuzz-XXXXXX").string();
        if (!mkdtemp(templ.data())) fail("cannot create a scratch folder under " + templ);
        path_ = templ;
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    std::filesystem::path path_;
};

// Writes `bytes` to the scratch file `name` and returns its path.
inline std::string write_scratch(const std::string& name, std::string_view bytes) {
    const std::filesystem::path p = ScratchDir::path() / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) fail("cannot write " + p.string());
    return p.string();
}

inline void check_finite(std::span<const Triangle> triangles, const std::string& what) {
    for (std::size_t i = 0; i < triangles.size(); ++i)
        if (!is_finite(triangles[i].v0) || !is_finite(triangles[i].v1) || !is_finite(triangles[i].v2))
            fail(what + " accepted triangle " + std::to_string(i) + " with a non-finite vertex");
}

// What every accepted scene must be: finite triangles, an image size the readers allow, and a
// camera that makes finite, unit-length rays, with the top row above the bottom one and the right
// column right of the left one (a flipped basis would render a mirrored image without an error).
// Returns primary rays through a grid of pixels.
inline std::vector<Ray> check_scene(const Scene& scene, const std::string& what) {
    if (scene.triangles.empty()) fail(what + " accepted a scene without triangles");
    check_finite(scene.triangles, what);
    if (scene.width < 1 || scene.height < 1 || scene.width > 65536 || scene.height > 65536)
        fail(what + " accepted an image of " + std::to_string(scene.width) + "x" + std::to_string(scene.height));
    const PinholeCamera camera(scene.camera, scene.width, scene.height);  // throws: a failed check too
    constexpr int kGrid = 5;
    std::vector<Ray> rays;
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
            const Ray r = camera.primary(i * (scene.width - 1) / (kGrid - 1), j * (scene.height - 1) / (kGrid - 1));
            if (!is_finite(r.org) || !is_finite(r.dir) || !(std::fabs(length(r.dir) - 1.f) < 1e-3f))
                fail(what + " accepted a camera whose primary ray is not finite and of unit length");
            rays.push_back(r);
        }
    // Top-left minus bottom-right: along the camera's up and against its right. The tolerance keeps
    // rounding out where the image is one pixel wide or high and that component is zero.
    const Vec3 diagonal = rays.front().dir - rays.back().dir;
    const Vec3 right = normalize(cross(scene.camera.look_at - scene.camera.position, scene.camera.up));
    const float tolerance = 1e-3f * length(diagonal);
    if (dot(diagonal, normalize(scene.camera.up)) < -tolerance || dot(diagonal, right) > tolerance)
        fail(what + " accepted a camera whose image is flipped");
    return rays;
}

// Rays that meet the geometry, not only the camera's: from `eye` to a triangle's centroid and to its
// first vertex (where the watertight test meets edges), for the first triangles.
inline void add_rays_to_triangles(std::span<const Triangle> triangles, Vec3 eye, std::vector<Ray>& rays) {
    constexpr std::size_t kAimed = 8;
    for (std::size_t i = 0; i < std::min(triangles.size(), kAimed); ++i) {
        const Triangle& t = triangles[i];
        for (const Vec3 target : {(t.v0 + t.v1 + t.v2) * (1.f / 3.f), t.v0}) {
            Ray r;
            r.org = eye;
            r.dir = target - eye;
            rays.push_back(r);
        }
    }
}

template <class T>
bool same_bits(const T& a, const T& b) {
    return std::bit_cast<std::array<unsigned char, sizeof(T)>>(a) ==
           std::bit_cast<std::array<unsigned char, sizeof(T)>>(b);
}

inline bool same_triangles(std::span<const Triangle> a, std::span<const Triangle> b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), same_bits<Triangle>);
}

// What any structure's answers must be, whatever its triangle test: a hit names a triangle and lies
// within the ray's interval.
inline void check_plausible(std::span<const Hit> hits, std::span<const Ray> rays, std::size_t triangles,
                            const std::string& name) {
    for (std::size_t i = 0; i < hits.size(); ++i)
        if (hits[i].is_hit() && (hits[i].prim >= triangles || !(hits[i].t >= rays[i].tnear && hits[i].t <= rays[i].tfar)))
            fail(name + " gave ray " + std::to_string(i) + " a hit outside its interval or the triangles");
}

// Traces `rays` through `accel`; the answers are plausible, and the closest hit and any hit agree
// unless the structure's triangle test is not cellrt's (Embree: rounding decides close calls).
struct Answers {
    std::vector<Hit> hits;
    std::vector<std::uint8_t> occluded;

    Answers(const Accelerator& accel, const std::string& name, std::span<const Ray> rays, std::size_t triangles,
            bool exact = true)
        : hits(rays.size()), occluded(rays.size()) {
        accel.intersect(rays, hits);
        accel.occluded(rays, occluded);
        check_plausible(hits, rays, triangles, name);
        for (std::size_t i = 0; exact && i < rays.size(); ++i)
            if (hits[i].is_hit() != (occluded[i] != 0))
                fail(name + ": the closest hit and the any hit of ray " + std::to_string(i) + " differ");
    }
};

inline Answers brute_force_answers(std::span<const Triangle> triangles, std::span<const Ray> rays) {
    AccelConfig config;
    config.kind = "brute";
    return Answers(*make_accelerator(triangles, config), "brute", rays, triangles.size());
}

// Fails unless `accel` gives the reference answers (brute force's) bit for bit.
inline void check_against(const Accelerator& accel, const std::string& name, std::span<const Ray> rays,
                          std::size_t triangles, const Answers& reference) {
    const Answers answers(accel, name, rays, triangles);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit &got = answers.hits[i], &want = reference.hits[i];
        if (!same_bits(got, want))
            fail(name + " disagrees with brute force on the closest hit of ray " + std::to_string(i) + ": prim " +
                 std::to_string(got.prim) + " t " + std::to_string(got.t) + ", brute force prim " +
                 std::to_string(want.prim) + " t " + std::to_string(want.t));
        if (answers.occluded[i] != reference.occluded[i])
            fail(name + " disagrees with brute force on the occlusion of ray " + std::to_string(i));
    }
}

// Whether structure `kind` must give brute force's answers bit for bit: all but Embree, which runs a
// triangle test of its own and so agrees only up to rounding (tests/test_embree.cpp).
inline bool exact_kind(const std::string& kind) { return kind != "embree"; }

// A configuration as parse_accel_config reads it, for messages.
inline std::string describe(const AccelConfig& config) {
    std::string s = config.kind + ":" + config.traversal + "+" + config.simd;
    for (const auto& [name, value] : config.params) s += (s.find('@') == std::string::npos ? "@" : ",") + name + "=" + value;
    return s;
}

// The scenes small enough to build every structure for, on every input that has one.
inline constexpr std::size_t kAgreementMaxTriangles = 64;

// Every structure with cellrt's triangle test (the trees, the wide BVH), with each of its
// single-ray traversals, with SIMD packets of each instruction set this machine has and with each
// value of its choice parameters (the build methods), built over `triangles` on one thread, must
// give brute force's answers to `rays`.
inline void check_agreement(std::span<const Triangle> triangles, std::span<const Ray> rays) {
    if (triangles.size() > kAgreementMaxTriangles) return;
    static const std::vector<AccelConfig> configs = [] {
        std::vector<AccelConfig> out;
        for (const std::string& kind : accelerator_kinds()) {
            if (kind == "brute" || !exact_kind(kind)) continue;  // the reference, or not bit for bit
            for (const std::string& traversal : accelerator_traversals(kind))
                out.push_back(parse_accel_config(kind + ":" + traversal));
            for (const detail::Isa isa : detail::available_isas())
                out.push_back(parse_accel_config(kind + "+" + to_string(isa)));
            for (const ParamSpec& param : accelerator_params(kind))
                for (const std::string& choice : param.choices)
                    if (choice != param.default_value) out.push_back(parse_accel_config(kind + "@" + param.name + "=" + choice));
        }
        for (AccelConfig& c : out) c.threads = 1;
        return out;
    }();
    const Answers reference = brute_force_answers(triangles, rays);
    for (const AccelConfig& config : configs)
        check_against(*make_accelerator(triangles, config), describe(config), rays, triangles.size(), reference);
}

// An accepted scene: check_scene, then the agreement on its camera's rays and on rays from the
// camera to its first triangles.
inline void check_scene_and_agreement(const Scene& scene, const std::string& what) {
    std::vector<Ray> rays = check_scene(scene, what);
    add_rays_to_triangles(scene.triangles, scene.camera.position, rays);
    check_agreement(scene.triangles, rays);
}

// A mesh that its loader read as `loaded`, opened as a bare mesh (load_scene, the path of `cellrt
// render model.obj`): the same triangles, framed by the default view. load_scene may refuse what the
// loader read: a mesh without triangles, or one so large that the default view's camera overflows.
inline void check_bare_mesh(const std::string& path, std::span<const Triangle> loaded) {
    const auto scene = parse_or_refuse([&] { return load_scene(path); }, path);
    if (!scene) return;
    if (!same_triangles(scene->triangles, loaded)) fail("load_scene read other triangles than the mesh's loader");
    check_scene_and_agreement(*scene, "load_scene of a bare mesh");
}

// A mesh target's input: written to a scratch file `name` and read by `load`; a refusal must name
// the file, and what is accepted must be finite. Nothing when refused.
template <class Load>
std::optional<std::vector<Triangle>> load_mesh(std::string_view text, const std::string& name, Load&& load,
                                               const std::string& what) {
    const std::string path = write_scratch(name, text);
    auto triangles = parse_or_refuse([&] { return load(path); }, path);
    if (triangles) check_finite(*triangles, what);
    return triangles;
}

// A reader's triangle count against what its file declares: exactly, or (where a face may be
// split into several triangles) at least.
inline void check_count(std::size_t read, std::size_t declared, bool at_least, const std::string& what) {
    if (at_least ? read >= declared : read == declared) return;
    fail(what + " read " + std::to_string(read) + " triangles, the file declares " +
         (at_least ? "at least " : "") + std::to_string(declared));
}

// A small fixed scene for the grammars that configure structures: a quad of two triangles sharing
// an edge, a copy of one of them (a tie, which the lower index wins), a triangle through the quad,
// a degenerate one, an axis-aligned sliver and a far one; seen by a camera at an angle.
inline const Scene& tiny_scene() {
    static const Scene scene = [] {
        Scene s;
        s.name = "tiny";
        s.triangles = {
            {{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {1.f, 1.f, 0.f}},
            {{-1.f, -1.f, 0.f}, {1.f, 1.f, 0.f}, {-1.f, 1.f, 0.f}},
            {{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {1.f, 1.f, 0.f}},
            {{-0.5f, 0.f, -0.5f}, {0.5f, 0.f, 0.5f}, {0.f, 0.8f, 0.f}},
            {{0.f, 0.f, 0.2f}, {0.5f, 0.5f, 0.2f}, {1.f, 1.f, 0.2f}},
            {{0.25f, -0.75f, 0.1f}, {0.25f, 0.75f, 0.1f}, {0.25f, 0.75f, 0.1001f}},
            {{5.f, 5.f, -4.f}, {6.f, 5.f, -4.f}, {5.f, 6.f, -4.f}},
        };
        s.camera = {{0.7f, 1.1f, 2.5f}, {0.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, 50.f};
        s.width = 7;
        s.height = 5;
        return s;
    }();
    return scene;
}

// Rays for tiny_scene(): its camera's grid, rays aimed at its triangles from the camera and from
// below, and rays along the axes (zero direction components) through the triangles' centroids.
inline const std::vector<Ray>& tiny_rays() {
    static const std::vector<Ray> rays = [] {
        const Scene& scene = tiny_scene();
        std::vector<Ray> out = check_scene(scene, "the tiny scene");
        add_rays_to_triangles(scene.triangles, scene.camera.position, out);
        add_rays_to_triangles(scene.triangles, {-0.3f, 0.4f, -3.f}, out);
        for (const Triangle& t : scene.triangles)
            for (const Vec3 dir : {Vec3{0.f, 0.f, -1.f}, Vec3{1.f, 0.f, 0.f}, Vec3{0.f, -1.f, 0.f}}) {
                Ray r;
                r.dir = dir;
                r.org = (t.v0 + t.v1 + t.v2) * (1.f / 3.f) - dir * 2.f;
                out.push_back(r);
            }
        out.back().tfar = 1.5f;  // ends before the triangle it aims at
        return out;
    }();
    return rays;
}

}  // namespace cellrt::fuzz
