// The message a call throws, for tests that compare the library's words exactly.
#pragma once

#include <functional>
#include <string>

#include "cellrt/error.hpp"

namespace cellrt::test {

// The message of the cellrt::Error that `call` throws, or "no error".
inline std::string error_of(const std::function<void()>& call) {
    try {
        call();
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace cellrt::test
