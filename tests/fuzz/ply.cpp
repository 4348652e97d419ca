// Stanford PLY (load_ply), then the same file as a bare mesh (load_scene). Accepted: finite
// vertices, at least one triangle per face the header declares, and the triangles read back bit for
// bit from the same mesh written as ASCII, binary little-endian and binary big-endian PLY, so that
// every format reads the counts, lists and values it declares.
#include <bit>
#include <cstring>

#include "cellrt/loaders.hpp"
#include "fuzz_support.hpp"
#include "scene/text_tokens.hpp"

namespace {

using cellrt::Triangle;

// The COUNT of the header's `element face COUNT` line, 0 without one; counted without the reader.
std::uint64_t declared_faces(std::string_view text) {
    while (!text.empty()) {
        const std::size_t nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
        const std::string_view keyword = cellrt::detail::next_token(line);
        if (keyword == "end_header") break;
        if (keyword != "element" || cellrt::detail::next_token(line) != "face") continue;
        return cellrt::fuzz::digit_runs(cellrt::detail::next_token(line)).at(0);
    }
    return 0;
}

enum class Encoding { ascii, little, big };

// `triangles` as a PLY file of three vertices per triangle (float x, y, z) and one face each
// (a uchar count, uint indices). ASCII floats are written with 9 significant digits, which read back
// to the same float.
std::string encode(std::span<const Triangle> triangles, Encoding encoding) {
    const char* format = encoding == Encoding::ascii ? "ascii" : encoding == Encoding::little ? "binary_little_endian"
                                                                                             : "binary_big_endian";
    std::string out = "ply\nformat " + std::string(format) + " 1.0\nelement vertex " +
                      std::to_string(3 * triangles.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                      std::to_string(triangles.size()) + "\nproperty list uchar uint vertex_indices\nend_header\n";
    const bool swap = (encoding == Encoding::big) != (std::endian::native == std::endian::big);
    auto put = [&](auto value) {
        char bytes[sizeof value];
        std::memcpy(bytes, &value, sizeof value);
        if (swap) std::reverse(std::begin(bytes), std::end(bytes));
        out.append(bytes, sizeof value);
    };
    char line[96];
    for (const Triangle& t : triangles)
        for (const cellrt::Vec3& v : {t.v0, t.v1, t.v2}) {
            if (encoding != Encoding::ascii) {
                for (int a = 0; a < 3; ++a) put(v[a]);
                continue;
            }
            std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", v[0], v[1], v[2]);
            out += line;
        }
    for (std::uint32_t i = 0; i < triangles.size(); ++i) {
        if (encoding != Encoding::ascii) {
            put(std::uint8_t{3});
            for (std::uint32_t k = 0; k < 3; ++k) put(3 * i + k);
            continue;
        }
        std::snprintf(line, sizeof line, "3 %u %u %u\n", 3 * i, 3 * i + 1, 3 * i + 2);
        out += line;
    }
    return out;
}

// What an accepted PLY must satisfy: its faces' triangles, and the same triangles read back from
// each encoding it is written in.
void check_accepted(std::string_view text, const std::vector<cellrt::Triangle>& triangles) {
    using namespace cellrt;
    fuzz::check_count(triangles.size(), declared_faces(text), true, "load_ply");
    for (const Encoding encoding : {Encoding::ascii, Encoding::little, Encoding::big}) {
        const std::string copy = fuzz::write_scratch("copy.ply", encode(triangles, encoding));
        if (!fuzz::same_triangles(load_ply(copy), triangles))
            fuzz::fail("the mesh written as PLY (" + std::to_string(static_cast<int>(encoding)) + ") reads back otherwise");
    }
    fuzz::check_bare_mesh(fuzz::write_scratch("mesh.ply", text), triangles);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text = cellrt::fuzz::as_text(data, size);
    auto load = [](const std::string& path) { return cellrt::load_ply(path); };
    if (const auto triangles = cellrt::fuzz::load_mesh(text, "mesh.ply", load, "load_ply")) check_accepted(text, *triangles);
    return 0;
}
