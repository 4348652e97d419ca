// Built-in scene specs (make_builtin_scene, builtin:NAME[?tris=N&seed=S]). Accepted: a spec that
// starts with `builtin:`, and a scene that check_scene passes, of the size asked for (within 10%
// from 1,000 triangles up, docs/SCENES.md).
#include <charconv>

#include "cellrt/builtin.hpp"
#include "fuzz_support.hpp"

namespace {

// make_builtin_scene accepts up to 10^8 triangles, which take seconds and gigabytes to make; the
// target skips specs whose scene would be larger than this, so that an execution stays short.
constexpr std::size_t kMaxTris = 4096;

// The triangle count `spec` asks for: its last `tris=` value, else its scene's default. A `tris=`
// that is not a key of the query, or not a number, is refused by the reader anyway.
std::size_t requested_tris(std::string_view spec) {
    constexpr std::string_view prefix = "builtin:";
    std::size_t tris = 0;
    if (spec.substr(0, prefix.size()) == prefix) {
        const std::string_view rest = spec.substr(prefix.size());
        const std::string_view name = rest.substr(0, rest.find('?'));
        for (const cellrt::BuiltinInfo& b : cellrt::builtin_scenes())
            if (b.name == name) tris = b.default_tris;
    }
    constexpr std::string_view key = "tris=";
    for (std::size_t at = spec.find(key); at != std::string_view::npos; at = spec.find(key, at + 1)) {
        const char* first = spec.data() + at + key.size();
        std::uint64_t value = 0;
        if (std::from_chars(first, spec.data() + spec.size(), value).ec == std::errc()) tris = value;
    }
    return tris;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace cellrt;
    const std::string spec(fuzz::as_text(data, size));
    const std::size_t tris = requested_tris(spec);
    if (tris > kMaxTris) return -1;  // not added to the corpus
    const auto scene = fuzz::parse_or_refuse([&] { return make_builtin_scene(spec); }, spec);
    if (!scene) return 0;
    if (spec.rfind("builtin:", 0) != 0) fuzz::fail("make_builtin_scene accepted a spec without 'builtin:': " + spec);
    const double ratio = static_cast<double>(scene->triangles.size()) / static_cast<double>(tris);
    if (tris >= 1000 && (ratio < 0.9 || ratio > 1.1))
        fuzz::fail(spec + " made " + std::to_string(scene->triangles.size()) + " triangles");
    fuzz::check_scene_and_agreement(*scene, spec);
    return 0;
}
