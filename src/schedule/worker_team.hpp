// Worker threads kept from frame to frame.
//
// Starting a thread per worker per frame costs more than the start itself: when a thread exits,
// glibc hands its stack pages back to the kernel (madvise, with a TLB shootdown on every core), so
// the next frame's thread faults its stack in again, and the SIMD packet kernels keep up to 128 KiB
// of rays there. Measured on the 2-core development machine: about 0.2 ms per two-thread frame for
// the starts and 0.4 ms more for 128 KiB of stack, a fixed cost that was up to a tenth of a 512 x 512
// frame (docs/SCALING.md). A team starts its threads once and wakes them for every run.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace cellrt::detail {

class WorkerTeam {
public:
    WorkerTeam() = default;
    WorkerTeam(const WorkerTeam&) = delete;
    WorkerTeam& operator=(const WorkerTeam&) = delete;
    ~WorkerTeam();

    // Runs job(w) for every w in [0, n) at once, on n threads of the team (worker w is always the same
    // thread; pinned to core w when `pin`, free to run anywhere otherwise), and returns when every
    // call has returned. The team grows to n threads on first need. One run at a time: a second
    // caller waits for the first; a job must not call run() itself. The calling thread runs
    // `meanwhile` (when given) while the workers run: the mailbox dispatch's master.
    void run(unsigned n, bool pin, const std::function<void(unsigned)>& job,
             const std::function<void()>& meanwhile = {});

private:
    void loop(unsigned w, std::uint64_t seen);
    void set_affinity(bool pin);

    std::mutex run_mutex_;
    std::vector<std::thread> threads_;
    bool pinned_ = false;
    // The current run, written by run() before `generation_` is bumped, read by the threads after.
    const std::function<void(unsigned)>* job_ = nullptr;
    unsigned active_ = 0;
    bool stopping_ = false;
    std::atomic<std::uint64_t> generation_{0};
    std::atomic<unsigned> remaining_{0};  // threads that have not yet finished the current run
};

// The process's team, shared by every render.
WorkerTeam& worker_team();

}  // namespace cellrt::detail
