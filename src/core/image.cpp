#include "cellrt/image.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

#include <stb_image_write.h>

#include "cellrt/error.hpp"
#include "core/files.hpp"

namespace cellrt {
namespace {

std::string encode_png(const Image& image) {
    std::vector<std::uint8_t> rgb(static_cast<std::size_t>(image.width) * image.height * 3);
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c)
            rgb[3 * i + c] = static_cast<std::uint8_t>(std::lround(255.f * linear_to_srgb(image.pixels[i][c])));
    std::string out;
    auto append = [](void* ctx, void* data, int size) {
        static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
    };
    if (!stbi_write_png_to_func(append, &out, image.width, image.height, 3, rgb.data(), image.width * 3))
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

}  // namespace

float linear_to_srgb(float linear) {
    const float c = std::clamp(linear, 0.f, 1.f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
}

void write_image(const Image& image, const std::string& path, bool overwrite) {
    const std::string ext = lower_extension(path);
    std::string bytes;
    if (ext == ".png") bytes = encode_png(image);
    else if (ext == ".pfm") bytes = encode_pfm(image);
    else throw Error(path + ": unknown image format '" + ext + "' (use .png or .pfm)");

    write_file_atomically(path, bytes, overwrite);
}

Image read_pfm(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open file for reading");
    std::string magic;
    int w = 0, h = 0;
    double scale = 0.0;
    in >> magic >> w >> h >> scale;
    in.get();
    if (!in || magic != "PF" || scale >= 0.0) throw Error(path + ": not a little-endian RGB PFM file");
    try {
        check_image_size(w, h);
    } catch (const Error& e) {
        throw Error(path + ": " + e.what());
    }
    Image image(w, h);
    for (int y = h - 1; y >= 0; --y)
        in.read(reinterpret_cast<char*>(&image.at(0, y)), static_cast<std::streamsize>(sizeof(Vec3)) * w);
    if (!in) throw Error(path + ": file is truncated");
    return image;
}

}  // namespace cellrt
