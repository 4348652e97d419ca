// Text fields of the programs' tables: CSV after RFC 4180 (a field holding a comma, a double quote or
// a line break quoted, its quotes doubled) and Markdown table cells (a `|` escaped, a line break a
// space). Scene names and configurations are the user's and hold any of these (found by audit,
// 2026-12-07: `kd@leaf_size=4,max_depth=20` shifted every later column of its row).
#pragma once

#include <string>
#include <string_view>

namespace cellrt::detail {

inline std::string csv_field(std::string_view text) {
    if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
    std::string quoted = "\"";
    for (const char c : text) {
        if (c == '"') quoted += '"';
        quoted += c;
    }
    return quoted + '"';
}

inline std::string markdown_cell(std::string_view text) {
    std::string cell;
    for (const char c : text) {
        if (c == '|') cell += '\\';
        cell += c == '\n' || c == '\r' ? ' ' : c;
    }
    return cell;
}

}  // namespace cellrt::detail
