// Whole-file reading and existence for the loaders (internal).
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cellrt/error.hpp"

namespace cellrt::detail {

inline std::string read_file(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a folder, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open file for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw Error(path + ": read error");
    return std::move(ss).str();
}

// Whether `path` names something that exists; throws cellrt::Error naming it when the system cannot
// tell (a name too long, a folder on the way that may not be searched).
inline bool file_exists(const std::string& path) {
    std::error_code ec;
    const bool exists = std::filesystem::exists(path, ec);
    if (ec) throw Error(path + ": cannot look the file up: " + ec.message());
    return exists;
}

}  // namespace cellrt::detail
