#include "cellrt/files.hpp"

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "cellrt/error.hpp"

namespace cellrt {

void write_file_atomically(const std::string& path, std::string_view bytes, bool overwrite) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!overwrite && fs::exists(path, ec)) throw Error(path + ": file exists (pass --overwrite to replace it)");
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) throw Error(path + ": directory '" + dir.string() + "' does not exist");
    const fs::path temp = dir / ("." + target.filename().string() + ".part" + std::to_string(::getpid()));
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
