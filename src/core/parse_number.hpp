// Numbers in text mesh files and in accelerator parameters (internal): std::from_chars (exact,
// locale-independent, the whole token or nothing) plus what C's strtod also accepts and from_chars
// does not: a leading '+', and a float too small for its type, which becomes the nearest float (zero
// or a subnormal) rather than an error.
#pragma once

#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>
#include <type_traits>

namespace cellrt::detail {

enum class ParsedNumber { Ok, Malformed, OutOfRange };

template <class T>
ParsedNumber parse_number(std::string_view tok, T& out) {
    if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-' && tok[1] != '+') tok.remove_prefix(1);
    const char* end = tok.data() + tok.size();
    const auto [ptr, ec] = std::from_chars(tok.data(), end, out);
    if (ptr != end || tok.empty() || (ec != std::errc() && ec != std::errc::result_out_of_range))
        return ParsedNumber::Malformed;
    if (ec == std::errc()) return ParsedNumber::Ok;
    if constexpr (std::is_floating_point_v<T>) {
        // Out of the type's range: too large, or so small that it underflows (then take the value of
        // a wider type, rounded).
        using Wide = std::conditional_t<std::is_same_v<T, float>, double, long double>;
        Wide wide = 0;
        if (std::from_chars(tok.data(), end, wide).ec == std::errc() &&
            std::fabs(wide) <= std::numeric_limits<T>::max()) {
            out = static_cast<T>(wide);
            return ParsedNumber::Ok;
        }
    }
    return ParsedNumber::OutOfRange;
}

}  // namespace cellrt::detail
