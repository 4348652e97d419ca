// Whole-file reading and existence, for the loaders and read_pfm (internal).
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <string>
#include <utility>

#include "cellrt/error.hpp"

namespace cellrt::detail {

// A regular file (after symbolic links) open for reading: a named pipe would wait for a writer that
// may never come, a device may never end. The file is opened without waiting (O_NONBLOCK, which
// regular files ignore) and what was opened is checked, so a pipe put in its place meanwhile is
// refused too. Errors are cellrt::Error naming the path.
class RegularFile {
public:
    explicit RegularFile(std::string path) : path_(std::move(path)) {
        fd_ = ::open(path_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
        if (fd_ < 0) throw Error(path_ + ": cannot open file for reading");
        struct stat st {};
        if (::fstat(fd_, &st) != 0) fail(": read error");
        if (S_ISDIR(st.st_mode)) fail(": is a folder, not a file");
        if (!S_ISREG(st.st_mode)) fail(": is not a regular file (a pipe, socket or device)");
        size_ = static_cast<std::size_t>(st.st_size);
    }
    RegularFile(const RegularFile&) = delete;
    RegularFile& operator=(const RegularFile&) = delete;
    ~RegularFile() { ::close(fd_); }

    std::size_t size() const { return size_; }  // when opened

    // Reads up to `n` bytes into `out`; fewer only at the end of the file.
    std::size_t read(char* out, std::size_t n) {
        std::size_t done = 0;
        while (done < n) {
            const ssize_t got = ::read(fd_, out + done, n - done);
            if (got == 0) break;
            if (got < 0) {
                if (errno == EINTR) continue;
                throw Error(path_ + ": read error");
            }
            done += static_cast<std::size_t>(got);
        }
        return done;
    }

private:
    [[noreturn]] void fail(const char* why) {
        ::close(fd_);
        throw Error(path_ + why);
    }
    std::string path_;
    int fd_ = -1;
    std::size_t size_ = 0;
};

// The whole of a regular file (RegularFile).
inline std::string read_file(const std::string& path) {
    RegularFile file(path);
    std::string text;
    text.reserve(file.size());
    char buffer[1 << 16];
    while (const std::size_t n = file.read(buffer, sizeof buffer)) text.append(buffer, n);
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
