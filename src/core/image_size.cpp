// Image sizes: their limits and their text (image.hpp). A unit of its own, so that code that only
// checks a size (the camera) does not link the image encoders and their PNG library.
#include <charconv>
#include <string>
#include <string_view>

#include "cellrt/error.hpp"
#include "cellrt/image.hpp"

namespace cellrt {
namespace {

// What is wrong with an image of `width` x `height` pixels, said of the size ("must have ..."), or
// nothing. The sides are long long so that a parsed side beyond int's range is refused as too large.
std::string image_size_problem(long long width, long long height) {
    if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
        return "must have both sides in [1, " + std::to_string(kMaxImageSide) + "]";
    if (width * height > kMaxImagePixels)
        return "has " + std::to_string(width * height) + " pixels, more than the largest image's " +
               std::to_string(kMaxImagePixels);
    return {};
}

}  // namespace

void check_image_size(int width, int height) {
    if (const std::string problem = image_size_problem(width, height); !problem.empty())
        throw Error("image size " + std::to_string(width) + "x" + std::to_string(height) + " " + problem);
}

std::pair<int, int> parse_image_size(const std::string& what, const std::string& text) {
    const std::string_view all(text);
    const std::size_t x = all.find('x');
    long long side[2] = {0, 0};
    const std::string_view parts[2] = {all.substr(0, x), x == std::string_view::npos ? "" : all.substr(x + 1)};
    for (int k = 0; k < 2; ++k) {
        const std::string_view p = parts[k];
        const auto [end, ec] = std::from_chars(p.data(), p.data() + p.size(), side[k]);
        if (p.empty() || end != p.data() + p.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
            throw Error(what + " '" + text + "' must be WIDTHxHEIGHT (two whole numbers, e.g. 1920x1080)");
        if (ec == std::errc::result_out_of_range) side[k] = p[0] == '-' ? -1 : kMaxImageSide + 1LL;
    }
    if (const std::string problem = image_size_problem(side[0], side[1]); !problem.empty())
        throw Error(what + " '" + text + "' " + problem);
    return {static_cast<int>(side[0]), static_cast<int>(side[1])};
}

}  // namespace cellrt
