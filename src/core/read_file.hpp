// Whole-file reading and existence, for the loaders and read_pfm (internal).
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <string>

#include "cellrt/error.hpp"

namespace cellrt::detail {

// Reads only a regular file (after symbolic links): a named pipe would wait for a writer that may
// never come, a device may never end. The file is opened without waiting (O_NONBLOCK, which regular
// files ignore) and what was opened is checked, so a pipe put in its place meanwhile is refused too.
inline std::string read_file(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throw Error(path + ": cannot open file for reading");
    const struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) throw Error(path + ": read error");
    if (S_ISDIR(st.st_mode)) throw Error(path + ": is a folder, not a file");
    if (!S_ISREG(st.st_mode)) throw Error(path + ": is not a regular file (a pipe, socket or device)");
    std::string text;
    text.reserve(static_cast<std::size_t>(st.st_size));
    char buffer[1 << 16];
    for (;;) {
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n == 0) break;
        if (n < 0) {
            if (errno == EINTR) continue;
            throw Error(path + ": read error");
        }
        text.append(buffer, static_cast<std::size_t>(n));
    }
    return text;
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
