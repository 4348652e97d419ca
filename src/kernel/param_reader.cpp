#include "param_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "cellrt/error.hpp"
#include "core/parse_number.hpp"
#include "named.hpp"

namespace cellrt::detail {

std::string join_names(const std::vector<std::string>& names) {
    std::string out;
    for (const auto& s : names) out += (out.empty() ? "" : ", ") + s;
    return out;
}

namespace {

std::vector<std::string> table_names(const ParamTable& table) {
    std::vector<std::string> names;
    for (const ParamSpec& p : table) names.push_back(p.name);
    return names;
}

}  // namespace

ParamReader::ParamReader(const ParamTable& table, const AccelConfig& config, std::string structure)
    : table_(table), given_(config.params), structure_(std::move(structure)) {
    std::vector<std::string> unknown;
    // Not a structured binding: clang before 16 cannot capture one in a lambda.
    for (const auto& given : given_)
        if (std::none_of(table_.begin(), table_.end(), [&](const ParamSpec& p) { return p.name == given.first; }))
            unknown.push_back(given.first);
    if (unknown.empty()) return;
    const std::string takes = table_.empty() ? structure_ + " takes none" : structure_ + " takes: " +
                                                                                join_names(table_names(table_));
    throw Error("unknown " + structure_ + " parameter(s): " + join_names(unknown) + " (" + takes + ")");
}

// Asking for a parameter the table lacks, or as another type, is a programming error of the structure.
const ParamSpec& ParamReader::spec(const std::string& name, ParamType type) {
    for (const ParamSpec& p : table_)
        if (p.name == name && p.type == type) {
            read_.push_back(name);
            return p;
        }
    throw std::logic_error(structure_ + " reads parameter '" + name + "' that its table does not declare so");
}

const std::string& ParamReader::text(const ParamSpec& spec, const std::string* default_value) const {
    const auto it = given_.find(spec.name);
    if (it != given_.end()) return it->second;
    return default_value ? *default_value : spec.default_value;
}

double ParamReader::number(const std::string& name, const std::string* default_value) {
    const ParamSpec& p = spec(name, ParamType::number);
    const std::string& t = text(p, default_value);
    // Numbers as in the scene files (core/parse_number.hpp): the whole text, decimal, whatever the C
    // locale (strtod took " 5" and "0x10", and would read "0.05" as 0 where the locale writes "0,05").
    double value = 0.0;
    const ParsedNumber parsed = parse_number(t, value);
    if (parsed == ParsedNumber::Malformed || (parsed == ParsedNumber::Ok && std::isnan(value)))
        throw Error(structure_ + " parameter " + name + "='" + t + "' is not a number");
    // Infinities, and numbers beyond a double's range, fail here too.
    if (parsed == ParsedNumber::OutOfRange || !(value >= p.min && value <= p.max))
        throw Error(structure_ + " parameter " + name + "=" + t + " is out of range " + param_range(p));
    return value;
}

int ParamReader::integer(const std::string& name) {
    const ParamSpec& p = spec(name, ParamType::integer);
    const std::string& t = text(p, nullptr);
    long value = 0;
    const ParsedNumber parsed = parse_number(t, value);
    if (parsed == ParsedNumber::Malformed)
        throw Error(structure_ + " parameter " + name + "='" + t + "' is not an integer");
    if (parsed == ParsedNumber::OutOfRange || static_cast<double>(value) < p.min || static_cast<double>(value) > p.max)
        throw Error(structure_ + " parameter " + name + "=" + t + " is out of range " + param_range(p));
    return static_cast<int>(value);
}

bool ParamReader::boolean(const std::string& name) {
    const std::string& t = text(spec(name, ParamType::boolean), nullptr);
    if (t == "1" || t == "true" || t == "on") return true;
    if (t == "0" || t == "false" || t == "off") return false;
    throw Error(structure_ + " parameter " + name + "='" + t + "' is not a boolean (true/false, on/off, 1/0)");
}

std::string ParamReader::choice(const std::string& name) {
    const ParamSpec& p = spec(name, ParamType::choice);
    const std::string& t = text(p, nullptr);
    if (std::find(p.choices.begin(), p.choices.end(), t) == p.choices.end())
        throw Error(structure_ + " parameter " + name + "='" + t + "' is not one of: " + join_names(p.choices));
    return t;
}

void ParamReader::finish() const {
    for (const ParamSpec& p : table_)
        if (std::find(read_.begin(), read_.end(), p.name) == read_.end())
            throw std::logic_error(structure_ + " declares parameter '" + p.name + "' but never reads it");
}

std::string param_text_exact(double v) {
    if (v == std::floor(v) && std::fabs(v) < 1e15) return param_number(v);
    char buf[32];
    const auto result = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, result.ptr);
}

std::string param_list(std::initializer_list<std::pair<const char*, std::string>> values) {
    std::string out;
    for (const auto& [name, value] : values) out += (out.empty() ? "" : ",") + (name + ("=" + value));
    return out;
}

std::string choose_traversal(const std::vector<std::string>& names, const std::string& requested,
                             const std::string& structure) {
    if (requested.empty()) return names.front();
    if (std::find(names.begin(), names.end(), requested) == names.end())
        throw Error("traversal '" + requested + "' is not offered by " + structure + " (choose one of: " +
                    join_names(names) + ")");
    return requested;
}

}  // namespace cellrt::detail
