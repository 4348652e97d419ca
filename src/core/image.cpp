#include "cellrt/image.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include <stb_image_write.h>

#include "cellrt/error.hpp"
#include "core/files.hpp"
#include "core/parse_number.hpp"
#include "core/read_file.hpp"

namespace cellrt {
namespace {

std::string encode_png(const Srgb8Image& image) {
    std::string out;
    auto append = [](void* ctx, void* data, int size) {
        static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
    };
    if (!stbi_write_png_to_func(append, &out, image.width, image.height, 3, image.rgb.data(), image.width * 3))
        throw Error("PNG encoding failed");
    return out;
}

// PFM stores rows bottom to top; a negative scale marks little-endian floats.
std::string encode_pfm(const Image& image) {
    static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian host");
    std::ostringstream out;
    out << "PF\n" << image.width << ' ' << image.height << "\n-1.0\n";
    for (int y = image.height - 1; y >= 0; --y)
        out.write(reinterpret_cast<const char*>(&image.at(0, y)), static_cast<std::streamsize>(sizeof(Vec3)) * image.width);
    return std::move(out).str();
}

// The pixel count of a w x h image; a negative side is a caller's mistake that would otherwise
// become a request for 2^64 pixels.
std::size_t pixel_count(const char* what, int w, int h) {
    if (w < 0 || h < 0)
        throw Error(std::string(what) + ": image size " + std::to_string(w) + "x" + std::to_string(h) + ": a side is negative");
    return static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
}

}  // namespace

Image::Image(int w, int h) : width(w), height(h), pixels(pixel_count("Image", w, h)) {}

Srgb8Image::Srgb8Image(int w, int h) : width(w), height(h), rgb(pixel_count("Srgb8Image", w, h) * 3) {}

float linear_to_srgb(float linear) {
    const float c = linear > 0.f ? std::fmin(linear, 1.f) : 0.f;  // NaN as 0, as the docs say
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
}

std::uint8_t srgb8_exact(float linear) {
    return static_cast<std::uint8_t>(std::lround(255.f * linear_to_srgb(linear)));
}

namespace {

// srgb8_exact by table, the same bytes in a fraction of the time (a power per channel was some 15 % of
// a 1080p frame's CPU time on cellrt-mpi's ranks). The byte never falls as the input rises through
// the floats of [0, 1] (all 1,065,353,217 of them checked: docs/DISTRIBUTED.md, "8-bit pixels"), so it is the number of
// thresholds t_1..t_255, the least float giving each byte, at or below the input. Non-negative
// floats order as their bit patterns: the floats of [0, 1) fall in buckets of 4,096 consecutive
// patterns, each holding the byte of its least float, and an input steps over the one threshold its
// bucket may hold (at the transfer function's slopes no bucket holds two; the constructor checks).
class Srgb8Table {
public:
    Srgb8Table() {
        threshold_[0] = 0.f;
        threshold_[256] = std::numeric_limits<float>::infinity();
        for (int k = 1; k < 256; ++k) {
            std::uint32_t lo = 0, hi = kOne;  // srgb8_exact(1) = 255 >= k
            while (lo < hi) {
                const std::uint32_t mid = lo + (hi - lo) / 2;
                if (srgb8_exact(std::bit_cast<float>(mid)) >= k) hi = mid;
                else lo = mid + 1;
            }
            threshold_[k] = std::bit_cast<float>(lo);
            if (k > 1 && (lo >> kBucketBits) == (std::bit_cast<std::uint32_t>(threshold_[k - 1]) >> kBucketBits))
                throw Error("sRGB table: two bytes begin within one bucket");
        }
        int b = 0;
        for (std::uint32_t i = 0; i < kBuckets; ++i) {
            const float first = std::bit_cast<float>(i << kBucketBits);
            while (b < 255 && first >= threshold_[b + 1]) ++b;
            base_[i] = static_cast<std::uint8_t>(b);
        }
    }
    std::uint8_t operator()(float x) const {
        // As unsigned patterns the floats of [0, 1) lie below 1's; above it lie the floats from 1 to
        // +infinity (255), then the positive NaNs and every negative float (0, as the formula gives).
        const auto bits = std::bit_cast<std::uint32_t>(x);
        if (bits >= kOne) return bits <= kInfinity ? 255 : 0;
        const int b = base_[bits >> kBucketBits];
        return static_cast<std::uint8_t>(b + (x >= threshold_[b + 1]));
    }

private:
    static constexpr std::uint32_t kOne = 0x3F800000u, kInfinity = 0x7F800000u, kBucketBits = 12,
                                   kBuckets = kOne >> kBucketBits;
    float threshold_[257];
    std::uint8_t base_[kBuckets];
};

const Srgb8Table& srgb8_table() {
    static const Srgb8Table table;
    return table;
}

}  // namespace

std::uint8_t srgb8(float linear) { return srgb8_table()(linear); }

Srgb8Image to_srgb8(const Image& image) {
    const Srgb8Table& table = srgb8_table();
    Srgb8Image out(image.width, image.height);
    // Fields set by hand could hold more pixels than width x height: written past `out` (found by
    // review, 2026-12-07).
    if (image.pixels.size() != out.rgb.size() / 3)
        throw Error("to_srgb8: an image of " + std::to_string(image.pixels.size()) + " pixels is not " +
                    std::to_string(image.width) + "x" + std::to_string(image.height));
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) out.rgb[3 * i + c] = table(image.pixels[i][c]);
    return out;
}

namespace {

// An image's size within the limits and its pixels as many as it says: an empty image made a file
// read_pfm refuses (and an empty PNG), a size its pixels did not match read past them.
void check_pixels(const std::string& path, int width, int height, std::size_t values, std::size_t per_pixel) {
    try {
        check_image_size(width, height);
    } catch (const Error& e) {
        throw Error(path + ": " + e.what());
    }
    if (values != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * per_pixel)
        throw Error(path + ": the image is " + std::to_string(width) + "x" + std::to_string(height) + " but holds " +
                    std::to_string(values / per_pixel) + " pixels");
}

}  // namespace

void write_png(const Srgb8Image& image, const std::string& path, bool overwrite) {
    if (lower_extension(path) != ".png") throw Error(path + ": 8-bit pixels are written as .png only");
    check_pixels(path, image.width, image.height, image.rgb.size(), 3);
    write_file_atomically(path, encode_png(image), overwrite);
}

void write_image(const Image& image, const std::string& path, bool overwrite) {
    const std::string ext = lower_extension(path);
    check_pixels(path, image.width, image.height, image.pixels.size(), 1);
    std::string bytes;
    if (ext == ".png") bytes = encode_png(to_srgb8(image));
    else if (ext == ".pfm") bytes = encode_pfm(image);
    else if (ext.empty()) throw Error(path + ": no extension to choose the image format by (use .png or .pfm)");
    else throw Error(path + ": unknown image format '" + ext + "' (use .png or .pfm)");

    write_file_atomically(path, bytes, overwrite);
}

// Opened as the loaders open files (core/read_file.hpp): only a regular file, so that a pipe or a
// device in the image's place is refused rather than waited on. The header is read as iostreams'
// `>> magic >> width >> height >> scale` and one character after it, then the rows straight into
// the image (bottom row first).
Image read_pfm(const std::string& path) {
    detail::RegularFile file(path);
    const Error not_pfm(path + ": not a little-endian RGB PFM file");
    std::string tokens[4];
    int read_tokens = 0;
    for (std::size_t header = 0;; ++header) {
        char c = 0;
        if (header == 256 || file.read(&c, 1) == 0) throw not_pfm;
        const bool space = c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f';
        if (!space) tokens[read_tokens] += c;
        else if (!tokens[read_tokens].empty() && ++read_tokens == 4) break;  // the character after the scale
    }
    int w = 0, h = 0;
    double scale = 0.0;
    using detail::ParsedNumber;
    if (tokens[0] != "PF" || detail::parse_number(tokens[1], w) != ParsedNumber::Ok ||
        detail::parse_number(tokens[2], h) != ParsedNumber::Ok ||
        detail::parse_number(tokens[3], scale) != ParsedNumber::Ok || !(scale < 0.0))
        throw not_pfm;
    try {
        check_image_size(w, h);
    } catch (const Error& e) {
        throw Error(path + ": " + e.what());
    }
    Image image(w, h);
    const std::size_t row = sizeof(Vec3) * static_cast<std::size_t>(w);
    for (int y = h - 1; y >= 0; --y)
        if (file.read(reinterpret_cast<char*>(&image.at(0, y)), row) != row) throw Error(path + ": file is truncated");
    return image;
}

}  // namespace cellrt
