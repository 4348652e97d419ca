// Whole-file reading for the loaders (internal).
#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include "cellrt/error.hpp"

namespace cellrt::detail {

inline std::string read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open file for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw Error(path + ": read error");
    return std::move(ss).str();
}

}  // namespace cellrt::detail
