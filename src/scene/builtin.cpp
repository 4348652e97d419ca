#include "cellrt/builtin.hpp"

#include <charconv>
#include <cmath>
#include <string_view>

#include "cellrt/error.hpp"
#include "mesh_builder.hpp"

namespace cellrt {
namespace {

struct BuiltinParams {
    std::size_t tris = 0;
    std::uint64_t seed = 1;
};

// A row of spheres of growing tessellation on a ground plane, with a box: the smallest scene with
// closed meshes, shadows and sky.
void make_spheres(Scene& scene, const BuiltinParams& p) {
    detail::MeshBuilder mesh(scene.triangles);
    mesh.quad({-6.f, 0.f, -6.f}, {-6.f, 0.f, 6.f}, {6.f, 0.f, 6.f}, {6.f, 0.f, -6.f});
    mesh.box({2.f, 0.f, -3.f}, {3.5f, 1.5f, -1.5f});
    // Five spheres share the triangle budget: segments = 2 * rings, about 4 * rings^2 triangles each.
    const double per_sphere = std::max<double>(16.0, static_cast<double>(p.tris) / 5.0);
    const int rings = std::max(3, static_cast<int>(std::sqrt(per_sphere / 4.0)));
    for (int i = 0; i < 5; ++i) {
        const float x = -4.f + 2.f * static_cast<float>(i);
        mesh.sphere({x, 0.8f, 1.f}, 0.8f, 2 * rings, rings);
    }
    scene.camera = {{0.f, 4.f, 9.f}, {0.f, 0.8f, 0.f}, {0.f, 1.f, 0.f}, 50.f};
    scene.light = {{-3.f, 8.f, 4.f}, {1.f, 1.f, 1.f}};
}

struct Generator {
    const char* name;
    const char* description;
    std::size_t default_tris;
    void (*make)(Scene&, const BuiltinParams&);
};

constexpr Generator kGenerators[] = {
    {"spheres", "five tessellated spheres and a box on a ground plane", 4000, &make_spheres},
};

std::uint64_t parse_unsigned(std::string_view value, const std::string& spec, std::string_view key) {
    std::uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (value.empty() || ec != std::errc() || ptr != value.data() + value.size())
        throw Error(spec + ": '" + std::string(key) + "' must be an unsigned integer, got '" + std::string(value) + "'");
    return v;
}

}  // namespace

std::vector<BuiltinInfo> builtin_scenes() {
    std::vector<BuiltinInfo> out;
    for (const Generator& g : kGenerators) out.push_back({g.name, g.description, g.default_tris});
    return out;
}

std::string default_scene_spec() { return "builtin:spheres"; }

Scene make_builtin_scene(const std::string& spec) {
    std::string_view rest = std::string_view(spec).substr(std::string_view("builtin:").size());
    const std::size_t q = rest.find('?');
    const std::string_view name = rest.substr(0, q);
    const Generator* gen = nullptr;
    for (const Generator& g : kGenerators)
        if (name == g.name) gen = &g;
    if (!gen) {
        std::string names;
        for (const Generator& g : kGenerators) names += (names.empty() ? "" : ", ") + std::string(g.name);
        throw Error(spec + ": unknown built-in scene '" + std::string(name) + "' (choose one of: " + names + ")");
    }
    BuiltinParams params;
    params.tris = gen->default_tris;
    std::string_view query = q == std::string_view::npos ? std::string_view{} : rest.substr(q + 1);
    while (!query.empty()) {
        const std::size_t amp = query.find('&');
        const std::string_view pair = query.substr(0, amp);
        query.remove_prefix(amp == std::string_view::npos ? query.size() : amp + 1);
        const std::size_t eq = pair.find('=');
        if (eq == std::string_view::npos) throw Error(spec + ": expected key=value, got '" + std::string(pair) + "'");
        const std::string_view key = pair.substr(0, eq), value = pair.substr(eq + 1);
        if (key == "tris") {
            params.tris = parse_unsigned(value, spec, key);
            if (params.tris < 100 || params.tris > 100'000'000)
                throw Error(spec + ": 'tris' must lie in [100, 100000000]");
        } else if (key == "seed") {
            params.seed = parse_unsigned(value, spec, key);
        } else {
            throw Error(spec + ": unknown key '" + std::string(key) + "' (known: tris, seed)");
        }
    }
    Scene scene;
    scene.name = std::string(name);
    gen->make(scene, params);
    validate_scene(scene, spec);
    return scene;
}

}  // namespace cellrt
