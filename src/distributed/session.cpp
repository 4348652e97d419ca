#include "distributed/session.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <new>
#include <thread>
#include <utility>
#include <vector>

#include "core/timer.hpp"

namespace cellrt::distributed {

Session::Session(int& argc, char**& argv, std::string program) : program_(std::move(program)) {
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    if (provided < MPI_THREAD_FUNNELED) {
        MPI_Finalize();
        throw Error("the MPI library does not support MPI_THREAD_FUNNELED");
    }
}

Session::~Session() { MPI_Finalize(); }

std::string Session::timeout_text() const {
    char text[48];
    std::snprintf(text, sizeof text, "%g s", static_cast<double>(timeout_.count()) / 1e3);
    return text;
}

namespace {

// Rank 0's word, before it ends the job, that it has said why: the others then end without a word.
constexpr int kTagAbort = 7;

}  // namespace

void Session::wait(MPI_Request& request, const std::string& what) const {
    Timer timer;
    int done = 0;
    for (MPI_Test(&request, &done, MPI_STATUS_IGNORE); !done; MPI_Test(&request, &done, MPI_STATUS_IGNORE)) {
        poll_ending(timer.seconds(), what);
        std::this_thread::sleep_for(kPollInterval);
    }
}

void Session::poll_ending(double waited, const std::string& what) const {
    if (!leader()) {
        int aborting = 0;
        MPI_Iprobe(0, kTagAbort, MPI_COMM_WORLD, &aborting, MPI_STATUS_IGNORE);
        if (aborting) std::_Exit(1);  // rank 0 has printed the cause and is ending the job
    }
    const double limit = static_cast<double>(timeout_.count()) / 1e3 * (leader() ? 1.0 : 2.0);
    if (waited > limit)
        abort("no answer to " + what + " within " + (leader() ? "" : "twice ") + timeout_text() +
              " (a rank stopped answering, or its step took longer than --rank-timeout)");
}

void Session::abort(const std::string& message) const {
    std::fprintf(stderr, "%s: error: rank %d: %s\n", program_.c_str(), rank_, message.c_str());
    std::fflush(stderr);
    if (leader()) {
        static const char word = 0;
        for (int r = 1; r < size_; ++r) {
            MPI_Request request;
            MPI_Isend(&word, 1, MPI_CHAR, r, kTagAbort, MPI_COMM_WORLD, &request);
            MPI_Request_free(&request);
        }
    }
    MPI_Abort(MPI_COMM_WORLD, 1);
    std::_Exit(1);  // MPI_Abort does not return; this only tells the compiler so
}

void Session::agree(const std::optional<std::string>& failure, const std::string& step) const {
    int failed = failure ? 1 : 0;
    std::vector<int> flags(static_cast<std::size_t>(size_));
    MPI_Request request;
    MPI_Iallgather(&failed, 1, MPI_INT, flags.data(), 1, MPI_INT, MPI_COMM_WORLD, &request);
    wait(request, "the agreement after " + step);
    const auto first = std::find(flags.begin(), flags.end(), 1);
    if (first == flags.end()) return;
    const int root = static_cast<int>(first - flags.begin());
    const auto others = std::count(flags.begin(), flags.end(), 1) - 1;
    // The lowest failing rank's message, to every rank.
    std::string message = rank_ == root ? *failure : std::string();
    unsigned long long length = message.size();
    MPI_Ibcast(&length, 1, MPI_UNSIGNED_LONG_LONG, root, MPI_COMM_WORLD, &request);
    wait(request, "the error message after " + step);
    message.resize(length);
    MPI_Ibcast(message.data(), static_cast<int>(length), MPI_CHAR, root, MPI_COMM_WORLD, &request);
    wait(request, "the error message after " + step);
    std::string what = "rank " + std::to_string(root) + ": " + message;
    if (others > 0) what += " (and " + std::to_string(others) + " other rank" + (others > 1 ? "s" : "") + ")";
    throw AgreedError(what);
}

void Session::together(const std::function<void()>& step, const std::string& name) const {
    std::optional<std::string> failure;
    try {
        step();
    } catch (const std::bad_alloc&) {
        failure = "out of memory";
    } catch (const std::exception& e) {
        failure = e.what();
    }
    agree(failure, name);
}

void Session::broadcast(void* data, std::size_t n, const std::string& what) const {
    constexpr std::size_t kChunk = std::size_t{1} << 30;  // MPI counts in int
    auto* p = static_cast<char*>(data);
    for (std::size_t at = 0; at < n; at += kChunk) {
        const auto count = static_cast<int>(std::min(kChunk, n - at));
        MPI_Request request;
        MPI_Ibcast(p + at, count, MPI_BYTE, 0, MPI_COMM_WORLD, &request);
        wait(request, what);
    }
}

std::vector<std::string> Session::gather(const std::string& mine, const std::string& what) const {
    const auto n = static_cast<std::size_t>(size_);
    int length = static_cast<int>(mine.size());
    if (mine.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw Error(what + ": " + std::to_string(mine.size()) + " bytes are more than MPI counts");
    std::vector<int> lengths(leader() ? n : 0), offsets(leader() ? n : 0);
    MPI_Request request;
    MPI_Igather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
    wait(request, what);
    std::string all;
    if (leader()) {
        long long total = 0;
        for (std::size_t r = 0; r < n; ++r) {
            offsets[r] = static_cast<int>(total);
            total += lengths[r];
        }
        if (total > std::numeric_limits<int>::max())
            throw Error(what + ": " + std::to_string(total) + " bytes are more than MPI counts");
        all.resize(static_cast<std::size_t>(total));
    }
    MPI_Igatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR, 0,
                 MPI_COMM_WORLD, &request);
    wait(request, what);
    std::vector<std::string> out;
    if (leader())
        for (std::size_t r = 0; r < n; ++r) out.push_back(all.substr(static_cast<std::size_t>(offsets[r]),
                                                                    static_cast<std::size_t>(lengths[r])));
    return out;
}

int Session::finish(int status) const {
    int agreed = 0;
    MPI_Request request;
    MPI_Iallreduce(&status, &agreed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD, &request);
    wait(request, "the end of the run");
    return agreed;
}

}  // namespace cellrt::distributed
