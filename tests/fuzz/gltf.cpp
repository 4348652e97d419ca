// glTF 2.0 (load_gltf), as .glb where the input starts with the binary container's magic and as
// .gltf otherwise, beside a buffer file the seeds name (quad.bin); then the same file as a scene
// (load_scene). Accepted: finite triangles, no more than the limit given, and a scene that load_scene
// reads with the same triangles and that passes the scene check and the structures' agreement on its
// view (the file's camera or the default one).
#include <cstring>

#include "cellrt/loaders.hpp"
#include "fuzz_support.hpp"

namespace {

// Far below the default limit, so that an input placing a mesh on many nodes is refused before it
// takes libFuzzer's memory limit.
constexpr std::size_t kFuzzMaxTriangles = 1 << 16;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    const float v[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const std::uint32_t i[6] = {0, 1, 2, 0, 2, 3};
    std::string bin(72, '\0');
    std::memcpy(bin.data(), v, 48);
    std::memcpy(bin.data() + 48, i, 24);
    cellrt::fuzz::write_scratch("quad.bin", bin);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace cellrt;
    const std::string_view bytes = fuzz::as_text(data, size);
    const std::string name = bytes.substr(0, 4) == "glTF" ? "scene.glb" : "scene.gltf";
    const auto gltf = fuzz::load_mesh(
        bytes, name, [](const std::string& p) { return load_gltf(p, kFuzzMaxTriangles).triangles; }, "load_gltf");
    if (!gltf) return 0;
    if (gltf->size() > kFuzzMaxTriangles) fuzz::fail("load_gltf made more triangles than its limit");
    const std::string path = (fuzz::ScratchDir::path() / name).string();
    const auto scene = fuzz::parse_or_refuse([&] { return load_scene(path); }, path);
    if (!scene) return 0;
    if (!fuzz::same_triangles(scene->triangles, *gltf)) fuzz::fail("load_scene read other triangles than load_gltf");
    fuzz::check_scene_and_agreement(*scene, "load_scene of a glTF file");
    return 0;
}
