// Linear float RGB images and their files: PNG (sRGB, 8 bit, for people) and PFM (exact floats,
// for comparing two renders bit for bit).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cellrt/vec.hpp"

namespace cellrt {

struct Image {
    int width = 0;
    int height = 0;
    std::vector<Vec3> pixels;  // row-major, row 0 at the top, linear radiance

    Image() = default;
    Image(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h) {}
    Vec3& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
    const Vec3& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

// Writes by extension: .png (sRGB-encoded, clamped) or .pfm (little-endian float RGB). The file is
// written beside the target under a temporary name and renamed into place, so an interrupted write
// never leaves a partial file under `path`. Refuses to replace an existing file unless `overwrite`.
// Throws cellrt::Error naming the path on any failure.
void write_image(const Image& image, const std::string& path, bool overwrite);

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

// The sRGB transfer function applied to one linear channel, clamped to [0, 1].
float linear_to_srgb(float linear);

}  // namespace cellrt
