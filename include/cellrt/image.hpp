// Linear float RGB images and their files: PNG (sRGB, 8 bit, for people) and PFM (exact floats,
// for comparing two renders bit for bit).
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include "cellrt/vec.hpp"
#include "cellrt/zeroed_array.hpp"

namespace cellrt {

struct Image {
    int width = 0;
    int height = 0;
    ZeroedArray<Vec3> pixels;  // row-major, row 0 at the top, linear radiance; zero until written

    Image() = default;
    Image(int w, int h);  // throws cellrt::Error for a negative side
    Vec3& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
    const Vec3& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

// Writes by extension: .png (sRGB-encoded, clamped, rows top to bottom) or .pfm (little-endian float
// RGB, rows bottom to top as the PFM format stores them; read_pfm flips them back). The file is
// written beside the target under a temporary name and renamed into place, so an interrupted write
// never leaves a partial file under `path`. Refuses to replace an existing file unless `overwrite`.
// Throws cellrt::Error naming the path on any failure, and for an image whose size check_image_size
// refuses (no pixels) or whose pixels are not width x height.
void write_image(const Image& image, const std::string& path, bool overwrite);

// A frame as a PNG holds it: 8-bit sRGB, three bytes a pixel (red, green, blue), row-major, row 0 at
// the top. cellrt-mpi's ranks send these for a frame written as PNG: a quarter of the float bytes.
struct Srgb8Image {
    int width = 0;
    int height = 0;
    ZeroedArray<std::uint8_t> rgb;

    Srgb8Image() = default;
    Srgb8Image(int w, int h);  // throws cellrt::Error for a negative side
};

// One linear channel's byte in a PNG: linear_to_srgb, scaled to [0, 255] and rounded (std::lround);
// NaN gives 0. srgb8 gives the bytes of srgb8_exact by a table (built on first use, 260 KiB).
std::uint8_t srgb8(float linear);
std::uint8_t srgb8_exact(float linear);

// The 8-bit sRGB pixels write_image puts in a PNG of `image`. Throws cellrt::Error where its pixels
// are not width x height.
Srgb8Image to_srgb8(const Image& image);

// Writes a PNG of 8-bit pixels, as write_image does (atomically; `overwrite` as there): for the pixels
// of to_srgb8(image) the very bytes of write_image(image) to a .png path. Throws cellrt::Error naming
// the path on any failure, when the path does not end in .png, and for an image write_image refuses.
void write_png(const Srgb8Image& image, const std::string& path, bool overwrite);

// Reads a PFM written by write_image (for tests and comparisons).
Image read_pfm(const std::string& path);

// The largest image: sides of at most kMaxImageSide pixels, and at most kMaxImagePixels pixels in all
// (16384 x 16384, 3 GiB of float pixels; stb's PNG writer counts its buffers' bytes in an int).
inline constexpr int kMaxImageSide = 65536;
inline constexpr long long kMaxImagePixels = 1LL << 28;

// Throws cellrt::Error "image size WxH ..." unless both sides lie in [1, kMaxImageSide] and the image
// has at most kMaxImagePixels pixels. render() (through PinholeCamera) and read_pfm() check so before
// they allocate an image's pixels.
void check_image_size(int width, int height);

// An image size written WIDTHxHEIGHT ("1920x1080"), two decimal numbers, checked by check_image_size;
// throws cellrt::Error naming `what` (an option, a field) otherwise.
std::pair<int, int> parse_image_size(const std::string& what, const std::string& text);

// The sRGB transfer function applied to one linear channel, clamped to [0, 1] (NaN as 0).
float linear_to_srgb(float linear);

}  // namespace cellrt
