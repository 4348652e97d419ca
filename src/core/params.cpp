#include "cellrt/params.hpp"

#include <cmath>
#include <cstdio>

namespace cellrt {

std::string param_number(double v) {
    char buf[32];
    if (v == std::floor(v) && std::fabs(v) < 1e15) std::snprintf(buf, sizeof buf, "%.0f", v);
    else std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
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
        case ParamType::boolean: return "true, false";
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
