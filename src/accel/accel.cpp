#include "cellrt/accel.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "cellrt/brute_force.hpp"
#include "cellrt/error.hpp"
#include "bih/bih_accel.hpp"
#include "kdtree/kd_accel.hpp"
#ifdef CELLRT_HAVE_EMBREE
#include "../embree/embree_accel.hpp"
#endif

namespace cellrt {

namespace {

using Factory = std::unique_ptr<Accelerator> (*)(std::span<const Triangle>, const AccelConfig&);

struct Entry {
    const char* kind;
    Factory make;
};

// The one list of structures this binary offers.
constexpr Entry kAccelerators[] = {
    {"brute", &make_brute_force},
    {"kd", &detail::make_kdtree},
    {"bih", &detail::make_bih},
#ifdef CELLRT_HAVE_EMBREE
    {"embree", &make_embree},
#endif
};

std::string join(const std::vector<std::string>& items) {
    std::string out;
    for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
    return out;
}

}  // namespace

std::vector<std::string> accelerator_kinds() {
    std::vector<std::string> kinds;
    for (const Entry& e : kAccelerators) kinds.emplace_back(e.kind);
    return kinds;
}

std::unique_ptr<Accelerator> make_accelerator(std::span<const Triangle> triangles, const AccelConfig& config) {
    for (const Entry& e : kAccelerators)
        if (config.kind == e.kind) return e.make(triangles, config);
    throw Error("unknown accelerator '" + config.kind + "' (choose one of: " + join(accelerator_kinds()) + ")");
}

AccelConfig parse_accel_config(std::string spec) {
    AccelConfig c;
    if (const auto at = spec.find('@'); at != std::string::npos) {
        const std::string params = spec.substr(at + 1);
        spec.resize(at);
        for (std::size_t b = 0; b <= params.size();) {
            const std::size_t e = std::min(params.find(',', b), params.size());
            const std::string kv = params.substr(b, e - b);
            const auto eq = kv.find('=');
            if (eq == std::string::npos || eq == 0)
                throw Error("accelerator parameter '" + kv + "' must have the form NAME=VALUE");
            c.params[kv.substr(0, eq)] = kv.substr(eq + 1);
            b = e + 1;
        }
    }
    if (const auto plus = spec.find('+'); plus != std::string::npos) {
        c.simd = spec.substr(plus + 1);
        spec.resize(plus);
    }
    const auto colon = spec.find(':');
    c.kind = spec.substr(0, colon);
    if (colon != std::string::npos) c.traversal = spec.substr(colon + 1);
    return c;
}

std::string traversal_or_default(const AccelConfig& config, const std::vector<std::string>& choices,
                                 const std::string& structure) {
    if (config.traversal.empty()) return choices.front();
    if (std::find(choices.begin(), choices.end(), config.traversal) == choices.end())
        throw Error("traversal '" + config.traversal + "' is not offered by " + structure +
                    " (choose one of: " + join(choices) + ")");
    return config.traversal;
}

ParamReader::ParamReader(const AccelConfig& config, std::string structure)
    : remaining_(config.params), structure_(std::move(structure)) {}

const std::string* ParamReader::take(const std::string& name) {
    auto it = remaining_.find(name);
    if (it == remaining_.end()) return nullptr;
    consumed_.push_back(it->second);
    remaining_.erase(it);
    return &consumed_.back();
}

double ParamReader::get_number(const std::string& name, double default_value, double min_value, double max_value) {
    const std::string* text = take(name);
    if (!text) return default_value;
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(text->c_str(), &end);
    if (text->empty() || *end != '\0' || errno == ERANGE || !std::isfinite(value))
        throw Error(structure_ + " parameter " + name + "='" + *text + "' is not a number");
    if (value < min_value || value > max_value)
        throw Error(structure_ + " parameter " + name + "=" + *text + " is out of range [" +
                    std::to_string(min_value) + ", " + std::to_string(max_value) + "]");
    return value;
}

int ParamReader::get_int(const std::string& name, int default_value, int min_value, int max_value) {
    const std::string* text = take(name);
    if (!text) return default_value;
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(text->c_str(), &end, 10);
    if (text->empty() || *end != '\0' || errno == ERANGE)
        throw Error(structure_ + " parameter " + name + "='" + *text + "' is not an integer");
    if (value < min_value || value > max_value)
        throw Error(structure_ + " parameter " + name + "=" + *text + " is out of range [" +
                    std::to_string(min_value) + ", " + std::to_string(max_value) + "]");
    return static_cast<int>(value);
}

bool ParamReader::get_bool(const std::string& name, bool default_value) {
    const std::string* text = take(name);
    if (!text) return default_value;
    if (*text == "1" || *text == "true" || *text == "on") return true;
    if (*text == "0" || *text == "false" || *text == "off") return false;
    throw Error(structure_ + " parameter " + name + "='" + *text + "' is not a boolean (true/false, on/off, 1/0)");
}

std::string ParamReader::get_choice(const std::string& name, const std::string& default_value,
                                    const std::vector<std::string>& choices) {
    const std::string* text = take(name);
    if (!text) return default_value;
    if (std::find(choices.begin(), choices.end(), *text) == choices.end())
        throw Error(structure_ + " parameter " + name + "='" + *text + "' is not one of: " + join(choices));
    return *text;
}

void ParamReader::finish() const {
    if (remaining_.empty()) return;
    std::vector<std::string> names;
    for (const auto& [k, v] : remaining_) names.push_back(k);
    throw Error("unknown " + structure_ + " parameter(s): " + join(names));
}

}  // namespace cellrt
