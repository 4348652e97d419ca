// View files (load_view_file): JSON naming a mesh beside it. The folder holds two small meshes the
// seeds name, quad.obj and quad.ply. Accepted: a scene check_scene passes (finite, an image size in
// range, a camera that makes rays), and the structures agree on it.
#include "cellrt/loaders.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    cellrt::fuzz::write_scratch("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    cellrt::fuzz::write_scratch("quad.ply",
                                "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace cellrt;
    const std::string path = fuzz::write_scratch("view.json", fuzz::as_text(data, size));
    // A mesh's error names the mesh, beside the view file: the folder is the common prefix.
    const auto scene = fuzz::parse_or_refuse([&] { return load_view_file(path); }, fuzz::ScratchDir::path().string());
    if (!scene) return 0;
    fuzz::check_scene_and_agreement(*scene, "load_view_file");
    return 0;
}
