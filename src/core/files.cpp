#include "core/files.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cellrt/error.hpp"

namespace cellrt {

namespace {

namespace fs = std::filesystem;

std::atomic<const std::atomic<bool>*> g_write_cancel{nullptr};

// What `path` names once links are followed: a regular file, a folder, a stream (a device, a pipe, a
// socket), or nothing. A path the system keeps under /dev or /proc that leads to a regular file this
// process holds open for writing counts as a stream: /dev/stdout or /dev/fd/3 redirected to a log
// file, which renaming over would replace (and truncating would wipe). Any other such path is the
// file it leads to (`/proc/self/cwd/scene.json`, `/dev/stdin < kept.json` were appended to without
// --overwrite and unchecked against the inputs; found by audit, 2026-12-07).
enum class Target { none, file, folder, stream };

// The process's own standard output or error when `path` leads to the same file, else null. Their
// bytes go through that stream, after what it holds buffered: a second descriptor of a redirected
// file (`--json /dev/stdout > log`) would write at an offset of its own, and the program's tables,
// flushed later at stdout's, would overwrite the results.
std::FILE* own_stream(const std::string& path) {
    struct stat named {};
    if (::stat(path.c_str(), &named) != 0) return nullptr;
    for (const auto& [fd, stream] : {std::pair{STDOUT_FILENO, stdout}, std::pair{STDERR_FILENO, stderr}}) {
        struct stat st {};
        if (::fstat(fd, &st) == 0 && st.st_dev == named.st_dev && st.st_ino == named.st_ino) return stream;
    }
    return nullptr;
}

bool system_path(const std::string& path) { return path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0; }

// Whether one of the process's descriptors is open for writing on the file `path` leads to (a shell's
// `> log` or `3>> log`). The descriptors are listed by /proc/self/fd; without /proc (fdescfs' /dev/fd
// has no such list), the first 1024 are asked.
bool open_for_writing(const std::string& path) {
    struct stat named {};
    if (::stat(path.c_str(), &named) != 0) return false;
    const auto writes_it = [&](int fd) {
        struct stat st {};
        if (::fstat(fd, &st) != 0 || st.st_dev != named.st_dev || st.st_ino != named.st_ino) return false;
        const int flags = ::fcntl(fd, F_GETFL);
        return flags >= 0 && (flags & O_ACCMODE) != O_RDONLY;
    };
    std::error_code ec;
    fs::directory_iterator it("/proc/self/fd", ec);
    if (ec) {
        for (int fd = 0; fd < 1024; ++fd)
            if (writes_it(fd)) return true;
        return false;
    }
    for (const fs::directory_iterator end; !ec && it != end; it.increment(ec)) {
        int fd = -1;
        const std::string name = it->path().filename().string();
        if (std::from_chars(name.data(), name.data() + name.size(), fd).ec == std::errc{} && writes_it(fd)) return true;
    }
    return false;
}

Target target_of(const std::string& path) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (!fs::exists(st)) return Target::none;
    if (fs::is_directory(st)) return Target::folder;
    if (!fs::is_regular_file(st)) return Target::stream;
    // The process's own output is a stream whatever names it (`--json log > log`, a link to /dev/stdout).
    if (own_stream(path) || (system_path(path) && open_for_writing(path))) return Target::stream;
    return Target::file;
}

// A path as the file it names: links and dots resolved where the system can, else as written. Its
// folder takes the temporary file, and the rename replaces the file, not a link to it. A link whose
// file is not there yet is followed too (as a shell's `>` follows it): it names that file, the one a
// write makes and another output may name directly.
fs::path file_named(const std::string& path) {
    std::error_code ec;
    fs::path p = fs::absolute(path, ec);
    if (ec) p = path;
    for (int hops = 0; fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
        // A loop, or a chain longer than the system follows: refused as `>` refuses it, rather than
        // a file put in place of the last link looked at.
        if (hops == 40) throw Error(path + ": too many levels of links");
        const fs::path to = fs::read_symlink(p, ec);
        if (ec) break;
        p = to.is_absolute() ? to : p.parent_path() / to;
    }
    const fs::path resolved = fs::weakly_canonical(p, ec);
    return ec ? p.lexically_normal() : resolved;
}

fs::path folder_of(const fs::path& file) { return file.has_parent_path() ? file.parent_path() : fs::path("."); }

// Appended, so that a stream that leads to a file (a shell's `> log`) is not truncated. A pipe no
// process reads yet is waited for in steps of 10 ms, which a signal ends (a blocked open was
// restarted after every signal, so that a Ctrl-C could not end a write to a pipe no one read; found
// by audit, 2026-12-07); once a reader is there, the bytes are written whole, as to a file.
void write_in_place(const std::string& path, std::string_view bytes) {
    if (std::FILE* stream = own_stream(path)) {
        if (std::fflush(stream) != 0 || std::fwrite(bytes.data(), 1, bytes.size(), stream) != bytes.size() ||
            std::fflush(stream) != 0)
            throw Error(path + ": write failed");
        return;
    }
    int fd = -1;
    while ((fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_NONBLOCK | O_CLOEXEC)) < 0) {
        const int error = errno;
        if (error == EINTR) continue;
        // ENXIO is also a socket's, or a terminal's where there is none: only a pipe is waited for.
        struct stat st {};
        if (error != ENXIO || ::stat(path.c_str(), &st) != 0 || !S_ISFIFO(st.st_mode))
            throw Error(path + ": cannot be opened for writing (" + std::strerror(error) + ")");
        const timespec step{0, 10'000'000};
        const std::atomic<bool>* cancel = g_write_cancel.load();
        if ((cancel && cancel->load()) || ::nanosleep(&step, nullptr) != 0)
            throw Error(path + ": interrupted while waiting for a reader of the pipe");
    }
    const auto failed = [&](int error) {
        ::close(fd);
        return Error(path + ": write failed (" + std::strerror(error) + ")");
    };
    if (const int flags = ::fcntl(fd, F_GETFL); flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0)
        throw failed(errno);
    for (std::size_t done = 0; done < bytes.size();) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n > 0) done += static_cast<std::size_t>(n);
        else if (n == 0 || errno != EINTR) throw failed(n == 0 ? EIO : errno);
    }
    if (::close(fd) != 0) {
        const int error = errno;
        throw Error(path + ": write failed (" + std::strerror(error) + ")");
    }
}

// A path under /dev or /proc that leads nowhere (`/dev/stdout` of a process whose stdout is closed):
// a file made there would be renamed over a link the system keeps.
void check_system_path(const std::string& path, Target kind) {
    if (kind == Target::none && system_path(path)) throw Error(path + ": is not there (a closed stream?)");
}

}  // namespace

void set_write_cancel(const std::atomic<bool>* flag) { g_write_cancel.store(flag); }

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

void write_file_atomically(const std::string& path, std::string_view bytes, bool overwrite) {
    const Target kind = target_of(path);
    check_system_path(path, kind);
    if (kind == Target::folder) throw Error(path + ": is a folder, not a file");
    if (kind == Target::stream) return write_in_place(path, bytes);
    if (kind == Target::file && !overwrite) throw Error(path + ": file exists and overwrite is off");
    const fs::path target = file_named(path);
    const fs::path dir = folder_of(target);
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw Error(path + ": directory '" + dir.string() + "' does not exist");
    // Hidden, beside the target, named after it as far as a name's 255 bytes allow, and unique to
    // this process and call.
    static std::atomic<unsigned> calls{0};
    // The target's name is cut so that the whole fits the folder's limit (eCryptfs allows 143 bytes,
    // where a name check_output_file passed made a temporary name the system refused).
    const std::string suffix = ".part" + std::to_string(::getpid()) + "-" + std::to_string(calls++);
    const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
    std::size_t keep = 200;
    if (name_max > 0) keep = std::min(keep, static_cast<std::size_t>(std::max(1L, name_max - 1 - static_cast<long>(suffix.size()))));
    std::string temp_name = ".";  // appended piece by piece: GCC 12 warns wrongly on "." + string (PR 105651)
    temp_name += target.filename().string().substr(0, keep);
    temp_name += suffix;
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
        const std::string why = ec.message();
        fs::remove(temp, ec);
        throw Error(path + ": cannot move the finished file into place (" + why + ")");
    }
}

void check_output_file(const std::string& path, bool overwrite) {
    if (path.empty()) throw Error("an output file's name is empty");
    const Target kind = target_of(path);
    check_system_path(path, kind);
    if (kind == Target::folder) throw Error(path + ": is a folder, not a file");
    if (kind == Target::stream) {  // written in place
        if (::access(path.c_str(), W_OK) != 0) {
            const int error = errno;
            throw Error(path + ": cannot be written (" + std::strerror(error) + ")");
        }
        return;
    }
    if (kind == Target::file && !overwrite) throw Error(path + ": file exists (pass --overwrite to replace it)");
    const fs::path file = file_named(path);
    const fs::path dir = folder_of(file);
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw Error(path + ": no folder " + dir.string() + " to write it in");
    if (::access(dir.c_str(), W_OK | X_OK) != 0) {  // the temporary file is made there
        const int error = errno;
        throw Error(path + ": cannot write in the folder '" + dir.string() + "' (" + std::strerror(error) + ")");
    }
    // A name the file system refuses was found when the finished file was moved into place, after
    // the work (found by audit, 2026-12-07).
    const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
    if (name_max > 0 && file.filename().string().size() > static_cast<std::size_t>(name_max))
        throw Error(path + ": the file's name is longer than the " + std::to_string(name_max) +
                    " bytes its folder's file system allows");
}

void check_output_folder(const std::string& option, const std::string& path) {
    const std::string named = option + " '" + path + "'";
    if (path.empty()) throw Error(option + ": the folder's name is empty");
    std::error_code ec;
    fs::path at = fs::absolute(path, ec);
    if (ec) throw Error(named + ": " + ec.message());
    // The nearest part of the path that exists must be a folder this process may write in.
    fs::path missing;  // the first part below it that does not exist, if any
    while (!fs::exists(at, ec) && at.has_parent_path() && at.parent_path() != at) {
        missing = at;
        at = at.parent_path();
    }
    if (!fs::is_directory(at, ec))
        throw Error(named + ": " + at.string() + " is a file, not a folder");
    if (::access(at.c_str(), W_OK | X_OK) != 0) {
        const int error = errno;
        throw Error(named + ": cannot write in " + at.string() + " (" + std::strerror(error) + ")");
    }
    // Where the system says yes but making a folder there fails (/proc for root), the folder is made
    // once and taken away again: a run should not find that out after its work.
    if (!missing.empty()) {
        if (::mkdir(missing.c_str(), 0700) == 0) ::rmdir(missing.c_str());
        else if (const int error = errno; error != EEXIST)
            throw Error(named + ": cannot make a folder in " + at.string() + " (" + std::strerror(error) + ")");
        else if (!fs::is_directory(missing, ec))  // a link to nothing, or a file made meanwhile
            throw Error(named + ": " + missing.string() + " is in the way of the folder (a link to nothing?)");
    }
}

void check_distinct_files(const std::vector<std::pair<std::string, std::string>>& outputs,
                          const std::vector<std::pair<std::string, std::string>>& inputs) {
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        const auto& [option, path] = outputs[i];
        if (path.empty() || target_of(path) == Target::stream) continue;  // /dev/null may take both
        for (std::size_t j = 0; j < i; ++j)
            if (!outputs[j].second.empty() && file_named(outputs[j].second) == file_named(path))
                throw Error(option + " " + path + " names the same file as " + outputs[j].first + " " +
                            outputs[j].second);
        for (const auto& [what, input] : inputs)
            if (!input.empty() && target_of(input) == Target::file && file_named(input) == file_named(path))
                throw Error(option + " " + path + " names the " + what + " " + input + ", which it would replace");
    }
}

}  // namespace cellrt
