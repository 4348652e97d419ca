// Software-cache layouts (parse_cache_layout, LINExSETS[xWAYS]). Accepted: a layout that
// validates, whose text form reads back to it, with the numbers written in the text; and the
// local-store model of each tree, both caches of that layout, gives brute force's answers where its
// budget admits the layout.
#include "accel/local_store_registry.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace cellrt;
    const std::string text(fuzz::as_text(data, size));
    const auto layout = fuzz::parse_or_refuse([&] { return parse_cache_layout("--node-cache", text); }, "--node-cache");
    if (!layout) return 0;
    validate_cache_layout(*layout, "an accepted layout");  // throws: a failed check too
    if (parse_cache_layout("to_string", layout->to_string()) != *layout)
        fuzz::fail("cache layout " + text + " does not read back from " + layout->to_string());
    const std::vector<std::uint64_t> numbers = fuzz::digit_runs(text);
    std::vector<std::uint64_t> fields{layout->line_bytes, layout->sets};
    if (numbers.size() == 3 || layout->ways != 1) fields.push_back(layout->ways);  // "x1" may be written
    if (numbers != fields)
        fuzz::fail("parse_cache_layout read " + layout->to_string() + " from text whose numbers are otherwise");

    const Scene& scene = fuzz::tiny_scene();
    const std::vector<Ray>& rays = fuzz::tiny_rays();
    const fuzz::Answers reference = fuzz::brute_force_answers(scene.triangles, rays);
    LocalStoreConfig local_store;
    local_store.node_cache = local_store.triangle_cache = *layout;
    for (const std::string& kind : accelerator_kinds())
        for (const CacheAccess access : {CacheAccess::sync, CacheAccess::async}) {
            AccelConfig config;
            config.kind = kind;
            config.threads = 1;
            local_store.access = access;
            const auto model = fuzz::parse_or_refuse(
                [&] { return make_local_store_accelerator(scene.triangles, config, local_store); });
            if (model) fuzz::check_against(**model, kind + " in the local store, " + text, rays, scene.triangles.size(), reference);
        }
    return 0;
}
