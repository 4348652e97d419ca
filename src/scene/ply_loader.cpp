// Strict Stanford PLY reader (Turk, "The PLY Polygon File Format", 1994): ASCII and binary of either
// byte order. cellrt reads PLY itself because Debian 12 packages no PLY library of its own (no rply,
// happly, tinyply or miniply) and the one importer it does package, assimp's, gives a vertex without a
// z property the coordinate 0 rather than an error; as with OBJ (obj_loader.cpp), a silently wrong
// mesh is the one outcome cellrt must never give. The subset needed is small: vertex x, y, z and the
// face index lists. Every other property and element is still read and checked, then dropped, so a
// malformed value anywhere in the file is an error.
#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>

#include "cellrt/error.hpp"
#include "cellrt/loaders.hpp"
#include "core/parse_number.hpp"
#include "core/read_file.hpp"
#include "text_tokens.hpp"

namespace cellrt {
namespace {

enum class Scalar : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct ScalarInfo {
    std::string_view names[2];  // the original name and its sized alias
    std::size_t bytes;
    bool integral;
    double min, max;  // range of an integral type
};

constexpr ScalarInfo kScalars[] = {
    {{"char", "int8"}, 1, true, -128.0, 127.0},
    {{"uchar", "uint8"}, 1, true, 0.0, 255.0},
    {{"short", "int16"}, 2, true, -32768.0, 32767.0},
    {{"ushort", "uint16"}, 2, true, 0.0, 65535.0},
    {{"int", "int32"}, 4, true, -2147483648.0, 2147483647.0},
    {{"uint", "uint32"}, 4, true, 0.0, 4294967295.0},
    {{"float", "float32"}, 4, false, 0.0, 0.0},
    {{"double", "float64"}, 8, false, 0.0, 0.0},
};

const ScalarInfo& info(Scalar s) { return kScalars[static_cast<std::size_t>(s)]; }

std::optional<Scalar> scalar_named(std::string_view name) {
    for (std::size_t i = 0; i < std::size(kScalars); ++i)
        if (name == kScalars[i].names[0] || name == kScalars[i].names[1]) return static_cast<Scalar>(i);
    return std::nullopt;
}

struct Property {
    std::string name;
    bool is_list = false;
    Scalar count_type = Scalar::UInt8;  // lists only
    Scalar type = Scalar::Float32;      // the value, or each list item
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
    std::size_t line = 0;  // of its `element` line, for header errors
};

enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct Header {
    Format format = Format::Ascii;
    std::vector<Element> elements;
    // What the reader needs, found once from the header: where the vertex and face elements are, and
    // which of their properties are x, y, z and the index list.
    std::size_t vertex_element = SIZE_MAX, face_element = SIZE_MAX;
    std::size_t xyz[3] = {};
    std::size_t face_indices = 0;
    std::size_t body_offset = 0;  // first byte after the end_header line
    std::size_t body_line = 0;    // its line number (ASCII)
};

using detail::next_token;

class HeaderParser {
public:
    HeaderParser(const std::string& path, std::string_view text) : path_(path), text_(text) {}

    Header parse() {
        if (next_line() != "ply") fail("not a PLY file: the first line must be 'ply'");
        bool have_format = false;
        for (;;) {
            std::string_view rest = next_line();
            const std::string_view keyword = next_token(rest);
            if (keyword == "end_header") {
                if (!next_token(rest).empty()) fail("unexpected text after end_header");
                break;
            }
            if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
            if (keyword == "format") {
                if (have_format) fail("a second format line");
                if (!header_.elements.empty()) fail("the format line must come before the elements");
                parse_format(rest);
                have_format = true;
            } else if (keyword == "element") {
                if (!have_format) fail("the format line must come before the elements");
                parse_element(rest);
            } else if (keyword == "property") {
                if (header_.elements.empty()) fail("property before any element");
                parse_property(rest);
            } else {
                fail("unknown header keyword '" + std::string(keyword) + "'");
            }
        }
        if (!have_format) fail("the header has no format line");
        header_.body_offset = pos_;
        header_.body_line = line_ + 1;
        find_mesh_elements();
        return header_;
    }

private:
    [[noreturn]] void fail(const std::string& what) const { fail_at(line_, what); }
    [[noreturn]] void fail_at(std::size_t line, const std::string& what) const {
        throw Error(path_ + ":" + std::to_string(line) + ": " + what);
    }

    // The next header line without its end of line; at the end of the file, an error.
    std::string_view next_line() {
        if (pos_ >= text_.size()) fail_at(line_ + 1, "unexpected end of file in the header (no end_header line)");
        const std::size_t nl = text_.find('\n', pos_);
        const std::size_t end = nl == std::string_view::npos ? text_.size() : nl;
        std::string_view line = text_.substr(pos_, end - pos_);
        pos_ = nl == std::string_view::npos ? text_.size() : nl + 1;
        ++line_;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        return line;
    }

    void parse_format(std::string_view rest) {
        const std::string_view format = next_token(rest), version = next_token(rest);
        if (format == "ascii") header_.format = Format::Ascii;
        else if (format == "binary_little_endian") header_.format = Format::BinaryLittleEndian;
        else if (format == "binary_big_endian") header_.format = Format::BinaryBigEndian;
        else
            fail("unknown format '" + std::string(format) +
                 "' (expected ascii, binary_little_endian or binary_big_endian)");
        if (version != "1.0") fail("unsupported PLY version '" + std::string(version) + "' (expected 1.0)");
        if (!next_token(rest).empty()) fail("unexpected text after the format version");
    }

    void parse_element(std::string_view rest) {
        Element e;
        e.name = std::string(next_token(rest));
        const std::string_view count = next_token(rest);
        const auto [ptr, ec] = std::from_chars(count.data(), count.data() + count.size(), e.count);
        if (e.name.empty() || count.empty() || (ec != std::errc() && ec != std::errc::result_out_of_range) ||
            ptr != count.data() + count.size() || !next_token(rest).empty())
            fail("expected 'element NAME COUNT' with COUNT a non-negative integer");
        if (ec == std::errc::result_out_of_range)
            fail("element count " + std::string(count) + " is out of range (at most 18446744073709551615)");
        for (const Element& other : header_.elements)
            if (other.name == e.name) fail("a second element '" + e.name + "'");
        e.line = line_;
        header_.elements.push_back(std::move(e));
    }

    Scalar scalar(std::string_view name) const {
        const std::optional<Scalar> s = scalar_named(name);
        if (!s)
            fail("unknown property type '" + std::string(name) +
                 "' (expected char, uchar, short, ushort, int, uint, float, double or int8 ... float64)");
        return *s;
    }

    void parse_property(std::string_view rest) {
        Property p;
        std::string_view type = next_token(rest);
        if (type == "list") {
            p.is_list = true;
            p.count_type = scalar(next_token(rest));
            if (!info(p.count_type).integral) fail("a list count type must be an integer type");
            type = next_token(rest);
        }
        p.type = scalar(type);
        p.name = std::string(next_token(rest));
        if (p.name.empty() || !next_token(rest).empty())
            fail("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
        Element& e = header_.elements.back();
        for (const Property& other : e.properties)
            if (other.name == p.name) fail("a second property '" + p.name + "' in element '" + e.name + "'");
        e.properties.push_back(std::move(p));
    }

    std::optional<std::size_t> property(const Element& e, std::string_view name) const {
        for (std::size_t i = 0; i < e.properties.size(); ++i)
            if (e.properties[i].name == name) return i;
        return std::nullopt;
    }

    void find_mesh_elements() {
        for (std::size_t i = 0; i < header_.elements.size(); ++i) {
            if (header_.elements[i].name == "vertex") header_.vertex_element = i;
            if (header_.elements[i].name == "face") header_.face_element = i;
        }
        for (const Element& e : header_.elements) {
            // A record must take at least a byte (binary) or a line (ASCII), so that a count cannot
            // make the reader loop over nothing.
            if (e.properties.empty() && e.count > 0) fail_at(e.line, "element '" + e.name + "' has no properties");
            // Vertex indices in another element (`tristrips`, as some scanners write) are geometry
            // this reader does not make triangles of: dropped, they were lost without a word (found
            // by audit, 2026-12-07).
            if (e.name != "face" && e.count > 0)
                for (const char* indices : {"vertex_indices", "vertex_index"})
                    if (property(e, indices))
                        fail_at(e.line, "element '" + e.name + "' holds vertex indices ('" + indices +
                                            "'), which this reader does not read: only element 'face' makes triangles");
        }
        if (header_.vertex_element == SIZE_MAX) fail("the header declares no element 'vertex'");
        const Element& v = header_.elements[header_.vertex_element];
        const char* axes[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a) {
            const auto p = property(v, axes[a]);
            if (!p) fail_at(v.line, "element 'vertex' has no property '" + std::string(axes[a]) + "'");
            if (v.properties[*p].is_list) fail_at(v.line, "vertex property '" + std::string(axes[a]) + "' is a list");
            header_.xyz[a] = *p;
        }
        if (header_.face_element == SIZE_MAX) return;
        const Element& f = header_.elements[header_.face_element];
        // Faces are resolved as they are read, so the vertices must already be known.
        if (header_.face_element < header_.vertex_element)
            fail_at(f.line, "element 'face' must come after element 'vertex'");
        auto p = property(f, "vertex_indices");
        if (!p) p = property(f, "vertex_index");
        if (!p) fail_at(f.line, "element 'face' has no list property 'vertex_indices' (or 'vertex_index')");
        if (!f.properties[*p].is_list || !info(f.properties[*p].type).integral)
            fail_at(f.line, "face property '" + f.properties[*p].name + "' must be a list of an integer type");
        header_.face_indices = *p;
    }

    const std::string& path_;
    std::string_view text_;
    std::size_t pos_ = 0, line_ = 0;
    Header header_;
};

// ASCII body: one element record per line, values separated by white space. Errors give the line.
class AsciiSource {
public:
    AsciiSource(const std::string& path, std::string_view body, std::size_t first_line)
        : path_(path), rest_(body), line_(first_line - 1) {}

    void begin_record(const Element& e, std::uint64_t index) {
        for (;;) {
            if (rest_.empty())
                fail_at(line_ + 1, "unexpected end of file: element '" + e.name + "' has " + std::to_string(e.count) +
                                       " records, the file ends after " + std::to_string(index));
            const std::size_t nl = rest_.find('\n');
            record_ = rest_.substr(0, nl);
            rest_.remove_prefix(nl == std::string_view::npos ? rest_.size() : nl + 1);
            ++line_;
            std::string_view probe = record_;
            if (!next_token(probe).empty()) break;  // blank lines between records are skipped
        }
        element_ = &e;
    }

    double read(Scalar type) {
        const std::string_view tok = next_token(record_);
        if (tok.empty()) fail("too few values for element '" + element_->name + "'");
        const ScalarInfo& t = info(type);
        if (t.integral) {
            std::int64_t v = 0;
            check(detail::parse_number(tok, v), t, tok);
            if (static_cast<double>(v) < t.min || static_cast<double>(v) > t.max)
                check(detail::ParsedNumber::OutOfRange, t, tok);
            return static_cast<double>(v);
        }
        if (type == Scalar::Float32) {
            float v = 0.f;
            check(detail::parse_number(tok, v), t, tok);
            return v;
        }
        double v = 0.0;
        check(detail::parse_number(tok, v), t, tok);
        return v;
    }

    void end_record() {
        if (!next_token(record_).empty()) fail("too many values for element '" + element_->name + "'");
    }

    void finish() {
        std::size_t line = line_ + 1;
        for (const char c : rest_) {
            if (c == '\n') ++line;
            else if (!detail::is_blank(c)) fail_at(line, "unexpected data after the last element");
        }
    }

    [[noreturn]] void fail(const std::string& what) const { fail_at(line_, what); }

private:
    void check(detail::ParsedNumber parsed, const ScalarInfo& t, std::string_view tok) const {
        if (parsed == detail::ParsedNumber::Malformed)
            fail("malformed " + std::string(t.names[0]) + " value '" + std::string(tok) + "'");
        if (parsed == detail::ParsedNumber::OutOfRange)
            fail("value " + std::string(tok) + " is out of range for " + std::string(t.names[0]));
    }

    [[noreturn]] void fail_at(std::size_t line, const std::string& what) const {
        throw Error(path_ + ":" + std::to_string(line) + ": " + what);
    }

    const std::string& path_;
    std::string_view rest_, record_;
    std::size_t line_;
    const Element* element_ = nullptr;
};

// Binary body: values packed without padding in the file's byte order. Errors name the element and
// the record's index (from 0).
class BinarySource {
public:
    BinarySource(const std::string& path, std::string_view body, bool big_endian)
        : path_(path), body_(body), swap_(big_endian != (std::endian::native == std::endian::big)) {}

    void begin_record(const Element& e, std::uint64_t index) {
        element_ = &e;
        index_ = index;
    }

    double read(Scalar type) {
        const std::size_t n = info(type).bytes;
        if (body_.size() - pos_ < n) fail("unexpected end of file (the binary data is truncated)");
        std::array<unsigned char, 8> b{};
        std::memcpy(b.data(), body_.data() + pos_, n);
        pos_ += n;
        if (swap_)
            for (std::size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
        switch (type) {
            case Scalar::Int8: return load<std::int8_t>(b);
            case Scalar::UInt8: return load<std::uint8_t>(b);
            case Scalar::Int16: return load<std::int16_t>(b);
            case Scalar::UInt16: return load<std::uint16_t>(b);
            case Scalar::Int32: return load<std::int32_t>(b);
            case Scalar::UInt32: return load<std::uint32_t>(b);
            case Scalar::Float32: return load<float>(b);
            case Scalar::Float64: return load<double>(b);
        }
        return 0.0;
    }

    void end_record() {}

    void finish() {
        if (pos_ != body_.size())
            throw Error(path_ + ": " + std::to_string(body_.size() - pos_) +
                        " bytes of unexpected data after the last element");
    }

    [[noreturn]] void fail(const std::string& what) const {
        throw Error(path_ + ": " + element_->name + " " + std::to_string(index_) + ": " + what);
    }

private:
    template <class T>
    static double load(const std::array<unsigned char, 8>& b) {
        T v;
        std::memcpy(&v, b.data(), sizeof(T));
        return static_cast<double>(v);
    }

    const std::string& path_;
    std::string_view body_;
    std::size_t pos_ = 0;
    bool swap_;
    const Element* element_ = nullptr;
    std::uint64_t index_ = 0;
};

// Reads every element in header order, keeping vertex positions and triangulating faces as fans.
template <class Source>
class BodyReader {
public:
    BodyReader(const Header& header, Source& source, std::size_t body_bytes)
        : header_(header), source_(source), body_bytes_(body_bytes) {}

    std::vector<Triangle> read() {
        for (std::size_t i = 0; i < header_.elements.size(); ++i) {
            const Element& e = header_.elements[i];
            if (i == header_.vertex_element) read_vertices(e);
            else if (i == header_.face_element) read_faces(e);
            else
                for (std::uint64_t r = 0; r < e.count; ++r) skip_record(e, r);
        }
        source_.finish();
        return std::move(triangles_);
    }

private:
    // A count from the header can be anything; reserving more than one item per byte of the file
    // would only let a corrupt header exhaust memory.
    std::size_t plausible(std::uint64_t count) const {
        return static_cast<std::size_t>(std::min<std::uint64_t>(count, body_bytes_));
    }

    void read_vertices(const Element& e) {
        vertices_.reserve(plausible(e.count));
        for (std::uint64_t r = 0; r < e.count; ++r) {
            source_.begin_record(e, r);
            Vec3 p;
            for (std::size_t k = 0; k < e.properties.size(); ++k) {
                const double v = read_property(e.properties[k]);
                for (int a = 0; a < 3; ++a)
                    if (k == header_.xyz[a]) p[a] = static_cast<float>(v);
            }
            if (!is_finite(p)) source_.fail("vertex coordinate is not finite (as a float)");
            source_.end_record();
            vertices_.push_back(p);
        }
    }

    void read_faces(const Element& e) {
        triangles_.reserve(plausible(e.count));
        for (std::uint64_t r = 0; r < e.count; ++r) {
            source_.begin_record(e, r);
            for (std::size_t k = 0; k < e.properties.size(); ++k) {
                if (k != header_.face_indices) {
                    read_property(e.properties[k]);
                    continue;
                }
                const Property& p = e.properties[k];
                const std::uint64_t n = list_length(p);
                if (n < 3) source_.fail("face needs at least three vertices, has " + std::to_string(n));
                corners_.clear();
                for (std::uint64_t c = 0; c < n; ++c) corners_.push_back(vertex_index(source_.read(p.type)));
                // Fan triangulation around the first corner.
                for (std::size_t c = 1; c + 1 < corners_.size(); ++c)
                    triangles_.push_back({vertices_[corners_[0]], vertices_[corners_[c]], vertices_[corners_[c + 1]]});
            }
            source_.end_record();
        }
    }

    std::size_t vertex_index(double index) const {
        if (index < 0 || index >= static_cast<double>(vertices_.size()))
            source_.fail("vertex index " + std::to_string(static_cast<long long>(index)) +
                         " is out of range (the file has " + std::to_string(vertices_.size()) + " vertices)");
        return static_cast<std::size_t>(index);
    }

    void skip_record(const Element& e, std::uint64_t r) {
        source_.begin_record(e, r);
        for (const Property& p : e.properties) read_property(p);
        source_.end_record();
    }

    std::uint64_t list_length(const Property& p) {
        const double n = source_.read(p.count_type);  // of an integer type: integral
        if (n < 0) source_.fail("list '" + p.name + "' has a negative length");
        return static_cast<std::uint64_t>(n);
    }

    // Reads one property (a scalar or a whole list) and returns the scalar's value.
    double read_property(const Property& p) {
        if (!p.is_list) return source_.read(p.type);
        for (std::uint64_t i = list_length(p); i > 0; --i) source_.read(p.type);
        return 0.0;
    }

    const Header& header_;
    Source& source_;
    std::size_t body_bytes_;
    std::vector<Vec3> vertices_;
    std::vector<std::size_t> corners_;
    std::vector<Triangle> triangles_;
};

}  // namespace

std::vector<Triangle> load_ply(const std::string& path) {
    const std::string text = detail::read_file(path);
    const Header header = HeaderParser(path, text).parse();
    const std::string_view body = std::string_view(text).substr(header.body_offset);
    if (header.format == Format::Ascii) {
        AsciiSource source(path, body, header.body_line);
        return BodyReader(header, source, body.size()).read();
    }
    BinarySource source(path, body, header.format == Format::BinaryBigEndian);
    return BodyReader(header, source, body.size()).read();
}

}  // namespace cellrt
