// The one exception type of cellrt. Its message is complete and meant for the user: it names the
// file and line, the JSON field or the option that is wrong, and what was expected.
#pragma once

#include <stdexcept>
#include <string>

namespace cellrt {

class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace cellrt
