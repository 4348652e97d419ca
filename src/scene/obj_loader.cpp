// Strict Wavefront OBJ reader. cellrt reads OBJ itself rather than through tinyobjloader because
// tinyobjloader accepts malformed numbers silently (a "v 1 x 2" becomes a vertex at (1, 0, 2)), and
// a silently wrong image is the one outcome cellrt must never give; the subset needed here (v and
// f) is small. Reading the whole file at once and parsing with std::from_chars loads Sponza's
// 7.6 MB in a few tens of milliseconds.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string_view>

#include "cellrt/error.hpp"
#include "cellrt/loaders.hpp"
#include "core/parse_number.hpp"
#include "core/read_file.hpp"
#include "text_tokens.hpp"

namespace cellrt {
namespace {

using detail::next_token;

class ObjParser {
public:
    explicit ObjParser(const std::string& path) : path_(path) {}

    std::vector<Triangle> parse(std::string_view text) {
        // A UTF-8 byte-order mark, as some Windows editors write, would make the first line's keyword
        // unknown and skip it: a first vertex lost shifted every index by one (found by audit, 2026-12-07).
        if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
        std::size_t line_no = 0;
        while (!text.empty()) {
            const std::size_t nl = text.find('\n');
            std::string_view line = text.substr(0, nl);
            text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
            ++line_no;
            line_ = line_no;
            // A carriage return before the line's end: old Mac line ends (CR alone), which would make
            // the whole file one line.
            if (const std::size_t cr = line.find('\r'); cr != std::string_view::npos && cr + 1 < line.size())
                fail("a carriage return inside the line: the file's lines end with CR alone (old Mac) or a CR doubled "
                     "before LF; convert them to LF or CRLF", line_);
            if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
            const std::string_view keyword = next_token(line);
            if (keyword.empty()) continue;
            // A backslash at a line's end joins the next line to it (OBJ's continuation), which this
            // reader does not do: the next line would be read as a statement of its own.
            if (ends_with_backslash(line.empty() ? keyword : line))
                fail("a line continued by '\\' is not supported: join it to the next line", line_);
            if (keyword == "v") parse_vertex(line);
            else if (keyword == "f" || keyword == "fo") parse_face(line);  // `fo`: OBJ's older name of `f`
            else refuse_geometry(keyword);
        }
        return resolve();
    }

private:
    static bool ends_with_backslash(std::string_view rest) {
        while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t' || rest.back() == '\r')) rest.remove_suffix(1);
        return !rest.empty() && rest.back() == '\\';
    }

    // Statements that make geometry this reader does not read: skipped, they would drop it without a
    // word (found by audit, 2026-12-07). Every other statement (vt, vn, vp, l, p, g, o, s, usemtl,
    // mtllib, ...) changes no triangle.
    void refuse_geometry(std::string_view keyword) const {
        if (keyword == "call" || keyword == "csh")
            fail("'" + std::string(keyword) + "' (statements run from another file or a shell) is not supported", line_);
        for (const char* free_form : {"cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
                                      "scrv", "sp", "end", "con", "bsp", "bzp", "cdc", "cdp", "res"})
            if (keyword == free_form)
                fail("free-form geometry ('" + std::string(keyword) + "') is not supported: only polygons (v and f)",
                     line_);
    }

    [[noreturn]] void fail(const std::string& what, std::size_t line) const {
        throw Error(path_ + ":" + std::to_string(line) + ": " + what);
    }

    float parse_float(std::string_view tok) const {
        float value = 0.f;
        const detail::ParsedNumber parsed = detail::parse_number(tok, value);
        if (parsed == detail::ParsedNumber::Malformed)
            fail("malformed number '" + std::string(tok) + "' in vertex", line_);
        if (parsed == detail::ParsedNumber::OutOfRange || !std::isfinite(value))
            fail("vertex coordinate '" + std::string(tok) + "' is not finite", line_);
        return value;
    }

    void parse_vertex(std::string_view rest) {
        Vec3 p;
        for (int axis = 0; axis < 3; ++axis) {
            const std::string_view tok = next_token(rest);
            if (tok.empty()) fail("vertex needs three coordinates", line_);
            p[axis] = parse_float(tok);
        }
        const std::string_view w = next_token(rest);
        if (!w.empty()) parse_float(w);
        if (!next_token(rest).empty()) fail("too many values in vertex", line_);
        vertices_.push_back(p);
    }

    // Face corners keep the index as written and the line, resolved once all vertices are known.
    struct Corner {
        std::int64_t index;
        std::size_t vertices_before;
    };

    // Whether a corner's texture and normal indices, after its vertex's ("/vt", "//vn", "/vt/vn"), are
    // integers where present: unused here, but a corner holding anything else is malformed.
    static bool valid_attributes(std::string_view after) {
        for (int part = 0; !after.empty(); ++part) {
            if (part == 2 || after.front() != '/') return false;
            after.remove_prefix(1);
            const std::string_view number = after.substr(0, after.find('/'));
            std::int64_t unused = 0;
            const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), unused);
            if (!number.empty() && (ptr != number.data() + number.size() || ec == std::errc::invalid_argument))
                return false;
            after.remove_prefix(number.size());
        }
        return true;
    }

    void parse_face(std::string_view rest) {
        const std::size_t first = corners_.size();
        for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest)) {
            const std::string_view pos = tok.substr(0, tok.find('/'));
            std::int64_t index = 0;
            const auto [ptr, ec] = std::from_chars(pos.data(), pos.data() + pos.size(), index);
            if (ptr != pos.data() + pos.size() || pos.empty() ||
                (ec != std::errc() && ec != std::errc::result_out_of_range) || !valid_attributes(tok.substr(pos.size())))
                fail("malformed face index '" + std::string(tok) + "'", line_);
            if (ec == std::errc::result_out_of_range)  // beyond 64 bits: no file has that many vertices
                fail("face index " + std::string(pos) + " is out of range", line_);
            if (index == 0) fail("face index 0 is invalid (OBJ indices start at 1)", line_);
            corners_.push_back({index, vertices_.size()});
        }
        const std::size_t n = corners_.size() - first;
        if (n < 3) fail("face needs at least three vertices, has " + std::to_string(n), line_);
        faces_.push_back({first, n, line_});
    }

    std::vector<Triangle> resolve() const {
        std::vector<Triangle> tris;
        for (const Face& f : faces_) {
            auto vertex = [&](std::size_t k) -> const Vec3& {
                const Corner& c = corners_[f.first + k];
                const std::int64_t i = c.index > 0 ? c.index - 1 : static_cast<std::int64_t>(c.vertices_before) + c.index;
                // A negative index counts back from the vertices before its line, not the file's.
                if (i < 0 || i >= static_cast<std::int64_t>(vertices_.size()))
                    fail("face index " + std::to_string(c.index) + " is out of range (" +
                             (c.index < 0 ? std::to_string(c.vertices_before) + " vertices before it"
                                          : "the file has " + std::to_string(vertices_.size()) + " vertices") +
                             ")",
                         f.line);
                return vertices_[static_cast<std::size_t>(i)];
            };
            // Fan triangulation around the first corner.
            for (std::size_t k = 1; k + 1 < f.count; ++k) tris.push_back({vertex(0), vertex(k), vertex(k + 1)});
        }
        return tris;
    }

    struct Face {
        std::size_t first, count, line;
    };

    std::string path_;
    std::size_t line_ = 0;
    std::vector<Vec3> vertices_;
    std::vector<Corner> corners_;
    std::vector<Face> faces_;
};

}  // namespace

std::vector<Triangle> load_obj(const std::string& path) {
    const std::string text = detail::read_file(path);
    return ObjParser(path).parse(text);
}

}  // namespace cellrt
