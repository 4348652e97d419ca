// Wavefront OBJ (load_obj), then the same file as a bare mesh (load_scene). Accepted: finite
// vertices, and as many triangles as the file's faces make as fans (a face of n corners, n - 2).
#include "cellrt/loaders.hpp"
#include "fuzz_support.hpp"
#include "scene/text_tokens.hpp"

namespace {

// The triangles the `f` statements of `text` declare, counted without the reader: the corners of
// each line whose first token is `f` or `fo` (OBJ's older name of `f`, which the reader takes since
// 2026-12-07: the count left it out, and CI's fuzzing found a file it declared 4 fewer triangles
// in), before any comment.
std::size_t declared_triangles(std::string_view text) {
    std::size_t triangles = 0;
    while (!text.empty()) {
        const std::size_t nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
        line = line.substr(0, line.find('#'));
        if (const std::string_view keyword = cellrt::detail::next_token(line); keyword != "f" && keyword != "fo")
            continue;
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
    const auto triangles = fuzz::load_mesh(text, "mesh.obj", [](const std::string& p) { return load_obj(p); }, "load_obj");
    if (!triangles) return 0;
    fuzz::check_count(triangles->size(), declared_triangles(text), false, "load_obj");
    fuzz::check_bare_mesh(fuzz::write_scratch("mesh.obj", text), *triangles);
    return 0;
}
