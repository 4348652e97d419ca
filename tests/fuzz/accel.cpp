// Accelerator specs (parse_accel_config, KIND[:TRAVERSAL][+SIMD][@NAME=VALUE,...]), built by
// make_accelerator over a small fixed scene. Accepted: a structure whose answers are brute force's
// bit for bit (Embree's only plausible: its own triangle test), whose report can be printed, and,
// for a tree traced one ray at a time, whose local-store model agrees too.
#include "accel/local_store_registry.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace cellrt;
    const std::string spec(fuzz::as_text(data, size));
    auto config = fuzz::parse_or_refuse([&] { return parse_accel_config(spec); });
    if (!config) return 0;
    config->threads = 1;  // libFuzzer runs one input at a time; threaded builds are the sanitizer suite's
    const Scene& scene = fuzz::tiny_scene();
    const std::vector<Ray>& rays = fuzz::tiny_rays();
    const auto accel = fuzz::parse_or_refuse([&] { return make_accelerator(scene.triangles, *config); });
    if (!accel) return 0;
    (*accel)->stats().figures();
    if (!fuzz::exact_kind(config->kind)) {
        fuzz::Answers(**accel, spec, rays, scene.triangles.size(), /*exact=*/false);
        return 0;
    }
    const fuzz::Answers reference = fuzz::brute_force_answers(scene.triangles, rays);
    fuzz::check_against(**accel, spec, rays, scene.triangles.size(), reference);
    const auto model = fuzz::parse_or_refuse([&] { return make_local_store_accelerator(scene.triangles, *config, {}); });
    if (model) fuzz::check_against(**model, spec + " in the local store", rays, scene.triangles.size(), reference);
    return 0;
}
