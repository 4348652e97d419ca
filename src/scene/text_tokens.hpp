// Splitting a line of a text mesh file into blank-separated tokens (internal, OBJ and PLY readers).
#pragma once

#include <string_view>

namespace cellrt::detail {

// Blanks within a line; '\r' is one, so CRLF line endings need no special case.
inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// The next token of `line`, removed from it; empty at the end of the line.
inline std::string_view next_token(std::string_view& line) {
    std::size_t b = 0;
    while (b < line.size() && is_blank(line[b])) ++b;
    std::size_t e = b;
    while (e < line.size() && !is_blank(line[e])) ++e;
    const std::string_view tok = line.substr(b, e - b);
    line.remove_prefix(e);
    return tok;
}

}  // namespace cellrt::detail
