// Image sizes (parse_image_size, WIDTHxHEIGHT). Accepted: both in [1, 65536], and the two numbers
// written in the text, whatever else the grammar allows around them.
#include "cellrt/image.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace cellrt;
    const std::string text(fuzz::as_text(data, size));
    const auto parsed = fuzz::parse_or_refuse([&] { return parse_image_size("--size", text); }, "--size");
    if (!parsed) return 0;
    const auto [w, h] = *parsed;
    if (w < 1 || h < 1 || w > 65536 || h > 65536) fuzz::fail("parse_image_size accepted a size out of range");
    const std::vector<std::uint64_t> numbers = fuzz::digit_runs(text);
    if (numbers.size() != 2 || numbers[0] != static_cast<std::uint64_t>(w) || numbers[1] != static_cast<std::uint64_t>(h))
        fuzz::fail("parse_image_size read " + std::to_string(w) + "x" + std::to_string(h) +
                   " from text whose numbers are otherwise");
    return 0;
}
