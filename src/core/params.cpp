#include "cellrt/params.hpp"

#include <charconv>
#include <cmath>

namespace cellrt {

// Written by std::to_chars, as printf's "%.0f" and "%g" would write them in the C locale, whatever
// the process's locale: the parameter reader reads these texts back (defaults included) with
// std::from_chars, which knows no other decimal point (a "%g" under a locale writing "0,1" made
// every default unreadable).
std::string param_number(double v) {
    char buf[32];
    const bool whole = v == std::floor(v) && std::fabs(v) < 1e15;
    const auto result = whole ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 0)
                              : std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 6);
    return std::string(buf, result.ptr);
}

namespace {

std::string join(const std::vector<std::string>& items) {
    std::string out;
    for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
    return out;
}

}  // namespace

std::string param_range(const ParamSpec& spec) {
    switch (spec.type) {
        case ParamType::boolean: return "true, false (or on, off, 1, 0)";
        case ParamType::choice: return join(spec.choices);
        default: {
            // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on a chain of operator+.
            std::string range = "[";
            range += param_number(spec.min);
            range += ", ";
            range += param_number(spec.max);
            range += "]";
            return range;
        }
    }
}

std::string param_table_markdown(const ParamTable& table) {
    std::string out = "| name | default | range | meaning |\n|---|---|---|---|\n";
    for (const ParamSpec& p : table)
        out += "| `" + p.name + "` | " + p.default_value + " | " + param_range(p) + " | " + p.meaning + " |\n";
    return out;
}

}  // namespace cellrt
