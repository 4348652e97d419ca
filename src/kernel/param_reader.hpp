// Reads a structure's build parameters from an AccelConfig against its ParamTable (cellrt/params.hpp):
// defaults and ranges come from the table alone, so the table that validates is the table users list
// and the documents print.
#pragma once

#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "cellrt/accelerator.hpp"
#include "cellrt/params.hpp"

namespace cellrt::detail {

class ParamReader {
public:
    // Throws cellrt::Error naming `structure` for a parameter of `config` that `table` lacks.
    ParamReader(const ParamTable& table, const AccelConfig& config, std::string structure);

    // The parameter's value, or its default (`default_value` in place of the table's where given: a
    // default that depends on another option). Throws cellrt::Error for a malformed or out-of-range value.
    double number(const std::string& name, const std::string* default_value = nullptr);
    int integer(const std::string& name);
    bool boolean(const std::string& name);
    std::string choice(const std::string& name);

    // Call after reading: a row of the table that was never read is a programming error of the
    // structure (its table would promise a parameter that changes nothing); throws std::logic_error.
    void finish() const;

private:
    const ParamSpec& spec(const std::string& name, ParamType type);
    const std::string& text(const ParamSpec& spec, const std::string* default_value) const;

    const ParamTable& table_;
    std::map<std::string, std::string> given_;
    std::string structure_;
    std::vector<std::string> read_;  // the rows read so far
};

// A parameter's value as a report gives it back: whole numbers as integers, others in the shortest
// text that reads back as the same double (param_number's six digits, for the tables, do not:
// 0.1234567 came back as 0.123457).
std::string param_text_exact(double v);

// NAME=VALUE,... in the order given: a report's parameters as KIND@... takes them back.
std::string param_list(std::initializer_list<std::pair<const char*, std::string>> values);

// The traversal `requested` among `names` (the default first), or the default when `requested` is
// empty. Throws cellrt::Error naming `structure` for one it does not offer.
std::string choose_traversal(const std::vector<std::string>& names, const std::string& requested,
                             const std::string& structure);

}  // namespace cellrt::detail
