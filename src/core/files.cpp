#include "core/files.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "cellrt/error.hpp"

namespace cellrt {

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

void write_file_atomically(const std::string& path, std::string_view bytes, bool overwrite) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!overwrite && fs::exists(path, ec)) throw Error(path + ": file exists and overwrite is off");
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) throw Error(path + ": directory '" + dir.string() + "' does not exist");
    std::string temp_name = ".";  // appended piece by piece: GCC 12 warns wrongly on "." + string (PR 105651)
    temp_name += target.filename().string();
    temp_name += ".part" + std::to_string(::getpid());
    const fs::path temp = dir / temp_name;
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        if (!out) throw Error(path + ": cannot write in '" + dir.string() + "'");
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        out.close();
        if (!out) {
            fs::remove(temp, ec);
            throw Error(path + ": write failed (disk full?)");
        }
    }
    fs::rename(temp, target, ec);
    if (ec) {
        fs::remove(temp, ec);
        throw Error(path + ": cannot move the finished file into place");
    }
}

}  // namespace cellrt
