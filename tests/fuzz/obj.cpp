// Wavefront OBJ (load_obj), then the same file as a bare mesh (load_scene). Accepted: finite
// vertices, and as many triangles as the file's faces make as fans (a face of n corners, n - 2).
#include "cellrt/loaders.hpp"
#include "fuzz_support.hpp"
#include "scene/text_tokens.hpp"

namespace {

// The triangles the `f` statements of `text` declare, counted without the reader: the corners of
// each line whose first token is `f`, before any comment.
std::size_t declared_triangles(std::string_view text) {
    std::size_t triangles = 0;
    while (!text.empty()) {
        const std::size_t nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
        line = line.substr(0, line.find('#'));
        if (cellrt::detail::next_token(line) != "f") continue;
        std::size_t corners = 0;
        while (!cellrt::detail::next_token(line).empty()) ++corners;
        triangles += corners - 2;  // an accepted face has at least three
    }
    return triangles;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace cellrt;
    const std::string_view text = fuzz::as_text(data, size);
    const std::string path = fuzz::write_scratch("mesh.obj", text);
    const auto triangles = fuzz::parse_or_refuse([&] { return load_obj(path); }, path);
    if (!triangles) return 0;
    fuzz::check_finite(*triangles, "load_obj");
    if (triangles->size() != declared_triangles(text))
        fuzz::fail("load_obj read " + std::to_string(triangles->size()) + " triangles, the faces declare " +
                   std::to_string(declared_triangles(text)));
    fuzz::check_bare_mesh(path, *triangles);
    return 0;
}
