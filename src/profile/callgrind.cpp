#include "callgrind.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "cellrt/error.hpp"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define CELLRT_CALLGRIND_REQUESTS 1
#endif

extern char** environ;

namespace cellrt::profile {
namespace fs = std::filesystem;

std::string temp_folder() {
    std::error_code ec;
    const fs::path folder = fs::temp_directory_path(ec);
    if (!ec) return folder.string();
    // The first of the variables the standard library reads, as it reads them (libstdc++).
    std::string named = " /tmp";
    for (const char* variable : {"TMPDIR", "TMP", "TEMP", "TEMPDIR"})
        if (const char* value = std::getenv(variable)) {
            named = " $" + std::string(variable) + " '" + value + "'";
            break;
        }
    throw Error("the temporary folder" + named + " is not a folder (" + ec.message() +
                "): set TMPDIR to one callgrind's runs can be made in");
}

namespace {

// A private temporary folder, removed with everything in it.
class TempDir {
public:
    TempDir() {
        std::string pattern = (fs::path(temp_folder()) / "cellrt-callgrind-XXXXXX").string();
        if (!::mkdtemp(pattern.data()))
            throw Error("cannot create a temporary folder: " + std::string(std::strerror(errno)));
        path_ = pattern;
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

// The last `n` non-empty lines of a text file, for error messages.
std::string tail(const fs::path& file, int n) {
    std::ifstream in(file);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) lines.push_back(line);
    std::string out;
    for (std::size_t i = lines.size() > static_cast<std::size_t>(n) ? lines.size() - n : 0; i < lines.size(); ++i)
        out += "\n  " + lines[i];
    return out;
}

// Runs argv with stdin from /dev/null and stdout and stderr into `log`; returns the wait status.
// Where `cancel` turns true the child is killed and reaped, and Error("cancelled") thrown: a
// signalled profile left valgrind running and its folder behind (found by review, 2026-12-07).
int spawn_and_wait(const std::vector<std::string>& args, const fs::path& log, const std::atomic<bool>* cancel) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    pid_t pid = 0;
    const int err = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (err != 0) throw Error("cannot start " + args[0] + ": " + std::strerror(err));
    int status = 0;
    for (;;) {
        const pid_t done = ::waitpid(pid, &status, cancel ? WNOHANG : 0);
        if (done == pid) return status;
        if (done < 0 && errno != EINTR) throw Error("waiting for " + args[0] + " failed: " + std::strerror(errno));
        if (cancel && cancel->load()) {
            ::kill(pid, SIGKILL);
            while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
            }
            throw Error("cancelled");
        }
        if (done == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
}

std::uint64_t parse_count(const std::string& word, const std::string& where) {
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
    if (ec != std::errc() || end != word.data() + word.size())
        throw Error(where + ": '" + word + "' is not an event count");
    return v;
}

}  // namespace

std::string find_valgrind() {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path ? path : "");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        const fs::path candidate = fs::path(dir.empty() ? "." : dir) / "valgrind";
        if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
    return {};
}

EventCounts parse_callgrind_totals(std::istream& in, const std::string& name) {
    std::vector<std::string> events;
    std::vector<std::uint64_t> totals, summary;
    int line_no = 0;
    for (std::string line; std::getline(in, line);) {
        ++line_no;
        const auto colon = line.find(':');
        if (colon == std::string::npos) continue;
        const std::string key = line.substr(0, colon);
        if (key != "events" && key != "totals" && key != "summary") continue;
        const std::string where = name + ":" + std::to_string(line_no);
        std::istringstream words(line.substr(colon + 1));
        std::vector<std::string> list;
        for (std::string w; words >> w;) list.push_back(w);
        if (key == "events") {
            events = list;
            continue;
        }
        if (events.empty()) throw Error(where + ": '" + key + ":' before the 'events:' line");
        if (list.size() > events.size())
            throw Error(where + ": " + std::to_string(list.size()) + " counts for " + std::to_string(events.size()) +
                        " events");
        std::vector<std::uint64_t>& values = key == "totals" ? totals : summary;
        values.assign(events.size(), 0);  // counts left off at the end are zero
        for (std::size_t i = 0; i < list.size(); ++i) values[i] = parse_count(list[i], where);
    }
    const std::vector<std::uint64_t>& values = totals.empty() ? summary : totals;
    if (values.empty()) throw Error(name + ": no 'totals:' or 'summary:' line (not a callgrind output file?)");
    std::map<std::string, std::uint64_t> by_name;
    for (std::size_t i = 0; i < events.size(); ++i) by_name[events[i]] = values[i];
    for (const char* e : {"Ir", "Bc", "Bcm", "Bi", "Bim"})
        if (!by_name.count(e))
            throw Error(name + ": no '" + e + "' event (callgrind must run with --branch-sim=yes)");
    EventCounts c;
    c.instructions = by_name["Ir"];
    c.branches = by_name["Bc"] + by_name["Bi"];
    c.mispredictions = by_name["Bcm"] + by_name["Bim"];
    return c;
}

EventCounts run_callgrind(const std::vector<std::string>& command, const CallgrindOptions& options) {
    const std::string valgrind = find_valgrind();
    if (valgrind.empty()) throw Error("valgrind not found on PATH (install the valgrind package, see packages.txt)");
    if (command.empty()) throw Error("run_callgrind: no command");
    const TempDir dir;
    const fs::path out = dir.path() / "callgrind.out", vg_log = dir.path() / "valgrind.log",
                   program_log = dir.path() / "program.log";
    const bool collect_at_start = options.toggle_collect.empty();
    std::vector<std::string> args = {valgrind,
                                     "--tool=callgrind",
                                     "--branch-sim=yes",
                                     "--cache-sim=no",
                                     // No gdbserver pipes in the temporary directory: a run killed
                                     // on cancel would leave them there.
                                     "--vgdb=no",
                                     "--callgrind-out-file=" + out.string(),
                                     "--log-file=" + vg_log.string(),
                                     std::string("--instr-atstart=") + (options.instrument_at_start ? "yes" : "no"),
                                     std::string("--collect-atstart=") + (collect_at_start ? "yes" : "no")};
    for (const std::string& f : options.toggle_collect) args.push_back("--toggle-collect=" + f);
    args.insert(args.end(), command.begin(), command.end());

    const int status = spawn_and_wait(args, program_log, options.cancel);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        const std::string how = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                                  : "signal " + std::to_string(WTERMSIG(status));
        throw Error("the callgrind run of " + command[0] + " failed (" + how + "):" + tail(program_log, 3) +
                    tail(vg_log, 3));
    }
    std::ifstream in(out);
    if (!in) throw Error("callgrind wrote no output file" + tail(vg_log, 3));
    const EventCounts counts = parse_callgrind_totals(in, out.string());
    if (counts.instructions == 0)
        throw Error("callgrind collected no instructions from " + command[0] +
                    (options.toggle_collect.empty() ? std::string(" (was instrumentation never started?)")
                                                    : " (no function matching --toggle-collect=" +
                                                          options.toggle_collect.front() + " ran?)"));
    return counts;
}

#ifdef CELLRT_CALLGRIND_REQUESTS
bool client_requests_available() { return true; }
void start_instrumentation() { CALLGRIND_START_INSTRUMENTATION; }
void stop_instrumentation() { CALLGRIND_STOP_INSTRUMENTATION; }
#else
bool client_requests_available() { return false; }
void start_instrumentation() {}
void stop_instrumentation() {}
#endif

}  // namespace cellrt::profile
