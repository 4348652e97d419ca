// Whole-file reading and existence for the loaders (internal).
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cellrt/error.hpp"

namespace cellrt::detail {

// Reads only a regular file (after symbolic links): opening a named pipe would wait for a writer that
// may never come, a device may never end.
inline std::string read_file(const std::string& path) {
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(path, ec);
    if (std::filesystem::is_directory(st)) throw Error(path + ": is a folder, not a file");
    if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
        throw Error(path + ": is not a regular file (a pipe, socket or device)");
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
