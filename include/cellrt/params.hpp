// Build parameters as a table (after Mitsuba 0.6's kd-tree): every parameter a structure accepts has
// a name, a type, a default, a range and one line of meaning. The table validates what a user gives
// (an unknown name or a value out of range is refused), lists the parameters (`cellrt info --params`)
// and is the parameter table of the structure's document (docs/KDTREE.md, docs/BIH.md), checked by a test.
#pragma once

#include <string>
#include <vector>

namespace cellrt {

enum class ParamType { number, integer, boolean, choice };

struct ParamSpec {
    std::string name;
    ParamType type = ParamType::number;
    std::string default_value;         // as a user would write it; validated like a user's value
    double min = 0.0, max = 0.0;       // number and integer: the closed range
    std::vector<std::string> choices;  // choice: the accepted values
    std::string meaning;               // one line
};

using ParamTable = std::vector<ParamSpec>;

// "[min, max]", "true, false (or on, off, 1, 0)" or "a, b, c": the values a parameter accepts, as the tables print them.
std::string param_range(const ParamSpec& spec);

// A number as the tables print it: whole numbers below 1e15 in full (2^20 as 1048576), others as %g
// (1e15 as 1e+15).
std::string param_number(double v);

// The table as Markdown: | name | default | range | meaning |.
std::string param_table_markdown(const ParamTable& table);

}  // namespace cellrt
