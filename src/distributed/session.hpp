// One MPI job as cellrt-mpi sees it (docs/DISTRIBUTED.md): the ranks of MPI_COMM_WORLD, the waits that
// give up with a message instead of hanging, and the agreement on a step's outcome that makes every
// rank fail together, with one message naming the rank at fault and its cause.
//
// Only the thread that made the session calls MPI (MPI_THREAD_FUNNELED): rank 0's own tracer is a
// thread that never does. Every wait polls its request and sleeps between polls, so a rank waiting
// for others leaves its cores to its tracer (Open MPI's blocking calls spin a core).
#pragma once

#include <mpi.h>

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cellrt/error.hpp"

namespace cellrt::distributed {

// The error every rank throws when a step failed on some rank: what() is "rank R: cause" of the
// lowest failing rank; rank 0 prints it, the others stay silent.
struct AgreedError : Error {
    using Error::Error;
};

// How long a rank waits for another before it gives up.
inline constexpr std::chrono::seconds kDefaultRankTimeout{120};

// The poll interval of every wait: short against a tile's milliseconds, long enough that a waiting
// thread costs its core nothing measurable (docs/DISTRIBUTED.md).
inline constexpr std::chrono::microseconds kPollInterval{500};

class Session {
public:
    // MPI_Init_thread; throws cellrt::Error when MPI cannot give MPI_THREAD_FUNNELED. `program` names
    // the program in the messages the session prints ("cellrt: error: ...").
    Session(int& argc, char**& argv, std::string program);
    ~Session();  // MPI_Finalize
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    int rank() const { return rank_; }
    int size() const { return size_; }
    bool leader() const { return rank_ == 0; }
    const std::string& program() const { return program_; }

    std::chrono::milliseconds timeout() const { return timeout_; }
    void set_timeout(std::chrono::milliseconds t) { timeout_ = t; }

    // The time-out as text ("120 s").
    std::string timeout_text() const;

    // Polls `request` until it completes. When it has not within the time-out (on ranks other than 0
    // twice the time-out, so that rank 0, which knows which rank is missing, speaks first), prints
    // "PROGRAM: error: rank R: no answer to WHAT within T s" and aborts the job (MPI_Abort: a rank that
    // stopped answering cannot take part in an orderly end).
    void wait(MPI_Request& request, const std::string& what) const;

    // One poll of wait() for a caller that runs its own loop: on ranks other than 0, ends this process
    // (status 1, without a message) once rank 0 has said that the job is ending; aborts as wait() does
    // once `waited` seconds exceed its time-out.
    void poll_ending(double waited, const std::string& what) const;

    // Prints "PROGRAM: error: rank R: MESSAGE" and ends the whole job with status 1. Rank 0 first tells
    // the others, which then end at their next wait without a message of their own.
    [[noreturn]] void abort(const std::string& message) const;

    // Every rank's outcome of one step (each rank calls it once per step, in the same order): returns
    // when no rank failed, and otherwise throws AgreedError on every rank.
    void agree(const std::optional<std::string>& failure, const std::string& step) const;

    // Runs `step` on this rank and agrees on the outcome: the exception of any rank becomes the
    // AgreedError of all.
    void together(const std::function<void()>& step, const std::string& name) const;

    // Rank 0's `n` bytes at `data` into every rank's (n the same on all), in chunks MPI can count.
    void broadcast(void* data, std::size_t n, const std::string& what) const;

    // Every rank's `mine`, in rank order, on rank 0 (the others get an empty list).
    std::vector<std::string> gather(const std::string& mine, const std::string& what) const;

    // The program's exit status agreed by all ranks: the largest of them.
    int finish(int status) const;

private:
    std::string program_;
    int rank_ = 0, size_ = 1;
    std::chrono::milliseconds timeout_ = kDefaultRankTimeout;
};

}  // namespace cellrt::distributed
