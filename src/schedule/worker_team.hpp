// Worker threads kept from frame to frame.
//
// Starting a thread per worker per frame costs more than the start itself: when a thread exits,
// glibc hands its stack pages back to the kernel (madvise, with a TLB shootdown on every core), so
// the next frame's thread faults its stack in again, and the SIMD packet kernels keep up to 128 KiB
// of rays there. Measured on the 2-core development machine: about 0.2 ms per two-thread frame for
// the starts and 0.4 ms more for 128 KiB of stack, a fixed cost that was up to a tenth of a 512 x 512
// frame (docs/SCALING.md). A team starts its threads once and wakes them for every run.
//
// Waking a sleeping thread costs more again: the kernel's wake-up, and in a virtual machine the host
// scheduling the halted virtual core back in (tens to hundreds of microseconds per thread on the
// 16-core machine of docs/SCALING.md). So after a run the threads poll for the next one for a while
// (`spin`) before they sleep, as OpenMP runtimes and TBB's workers do, and frames drawn back to back
// find the team awake. The calling thread is job 0, as OpenMP's master thread is thread 0: N jobs
// take N threads, not N + 1 on N cores, and one wake-up fewer. Each thread waits on a word of its
// own, and a run of N jobs wakes only the N - 1 threads it needs: a one-worker frame after a
// sixteen-worker one wakes nobody (on the 2-core development machine, waking the idle thread for
// nothing cost the one-worker frame about 45 microseconds).
#pragma once

#ifdef __linux__
#include <sched.h>
#endif

#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
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

    // Runs job(j) for every j in [0, n) at once and returns when every call has returned: job 0 on
    // the calling thread, job j > 0 on thread j - 1 of the team (always the same thread; the team
    // grows to n - 1 threads on first need; threads beyond n - 1 are left as they are). With `pin`,
    // job j runs on the j-th core the caller may use, modulo their count (the caller's own affinity is
    // restored afterwards); otherwise anywhere the caller may run.
    // After the run the threads that took part poll for their next one for `spin` before they sleep
    // (0: sleep at once). One run at a time: a second caller waits for the first; a job must not call
    // run() itself. An exception from any job is rethrown once every job has returned (the first one
    // thrown, when several are), so a job that cannot go on must let the others know it stopped.
    // Throws cellrt::Error when the system refuses to start a thread; the team stays as it was.
    void run(unsigned n, bool pin, std::chrono::microseconds spin, const std::function<void(unsigned)>& job);

private:
    // A thread's wake-up word, on a cache line of its own: run() bumps it to hand the thread a run.
    struct alignas(64) Signal {
        std::atomic<std::uint64_t> generation{0};
    };

    void loop(unsigned t, Signal& signal);
    // `allowed`: the cores the caller may use, in order.
    void set_affinity(bool pin, const std::vector<int>& allowed);
    // Runs job(j), keeping the first exception of the run in failure_.
    void run_job(unsigned j);

    std::mutex run_mutex_;
    std::vector<std::thread> threads_;
    std::vector<std::unique_ptr<Signal>> signals_;  // signals_[t]: thread t's; kept in place as the team grows
    bool pinned_ = false;
#ifdef __linux__
    // The cores the first free_threads_ threads were last set to run on, by a free run (0: none set).
    cpu_set_t free_set_{};
    std::size_t free_threads_ = 0;
#endif
    // The current run, written by run() before it bumps the threads' signals, read by them after.
    const std::function<void(unsigned)>* job_ = nullptr;
    bool stopping_ = false;
    std::atomic<std::int64_t> spin_microseconds_{0};
    std::atomic<unsigned> remaining_{0};  // threads that have not yet finished the current run
    std::mutex failure_mutex_;
    std::exception_ptr failure_;  // the current run's first exception
};

// The process's team, shared by every render; its threads live as long as the process.
WorkerTeam& worker_team();

}  // namespace cellrt::detail
