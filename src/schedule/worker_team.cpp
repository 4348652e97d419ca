#include "worker_team.hpp"

#include <algorithm>
#include <exception>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#ifdef __linux__
#include <pthread.h>
#include <sched.h>
#endif

#include "cellrt/error.hpp"

namespace cellrt::detail {
namespace {

// Waits until `value` no longer holds `old` and returns what it holds then: polls for up to `spin`
// (yielding between polls, so that a machine with more threads than cores still makes progress),
// then sleeps in the kernel (atomic::wait returns only once the value differs from `old`).
template <class T>
T wait_for_change(const std::atomic<T>& value, T old, std::chrono::microseconds spin) {
    const auto until = std::chrono::steady_clock::now() + spin;
    for (;;) {
        const T now = value.load(std::memory_order_acquire);
        if (now != old) return now;
        if (std::chrono::steady_clock::now() >= until) break;
        std::this_thread::yield();
    }
    value.wait(old, std::memory_order_acquire);
    return value.load(std::memory_order_acquire);
}

// Whether this thread is running a job of the team: a run started from there (a packet's trace, a
// render's progress callback calling render or run_packets) would wait for the team it is part of.
thread_local bool t_in_job = false;

}  // namespace

WorkerTeam::~WorkerTeam() {
    {
        std::lock_guard lock(run_mutex_);
        stopping_ = true;
        for (const auto& s : signals_) {
            s->generation.fetch_add(1, std::memory_order_release);
            s->generation.notify_one();
        }
    }
    for (std::thread& t : threads_) t.join();
}

void WorkerTeam::run(unsigned n, bool pin, std::chrono::microseconds spin, const std::function<void(unsigned)>& job) {
    // Found by audit (2026-12-07): render() from a progress callback, or run_packets from a trace,
    // waited for ever.
    if (t_in_job)
        throw Error("a frame was started from inside a frame (a progress callback or a packet's trace): frames run "
                    "one at a time on the process's one team of workers");
    std::lock_guard lock(run_mutex_);
    while (threads_.size() + 1 < n) {
        // A new thread's signal starts at 0 and the thread waits for it to change: the first run it
        // takes part in is the first bump, whether that comes before or after the thread starts. The
        // signal joins the team only once its thread has started (a start that fails throws and
        // leaves the team as it was: thread t always waits on signals_[t]).
        const auto t = static_cast<unsigned>(threads_.size());
        auto signal = std::make_unique<Signal>();
        threads_.reserve(threads_.size() + 1);
        signals_.reserve(signals_.size() + 1);
        try {
            threads_.emplace_back([this, t, &s = *signal] { loop(t, s); });
        } catch (const std::system_error& e) {
            throw Error("cannot start a worker thread (" + std::to_string(t) + " running, " + std::to_string(n - 1) +
                        " needed): " + e.code().message());
        }
        signals_.push_back(std::move(signal));
    }
#ifdef __linux__
    // The cores the caller may use, in order: job j is pinned to the j-th of them, so that a run under
    // taskset or a cpuset stays on the cores it was given (job j was pinned to the machine's core j,
    // outside the set, where the system refused it and the run went unpinned; found by audit,
    // 2026-12-07).
    // Read on every run, free ones too: threads inherit the affinity of the thread that starts them,
    // and a team started by a render from a thread confined to one core kept every later free run's
    // helpers on that core, whoever called (found by audit, 2026-12-07). One system call a run.
    cpu_set_t caller_affinity;
    CPU_ZERO(&caller_affinity);
    std::vector<int> allowed;
    pthread_getaffinity_np(pthread_self(), sizeof caller_affinity, &caller_affinity);
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &caller_affinity)) allowed.push_back(c);
    set_affinity(pin, allowed);
    if (pin && !allowed.empty()) {
        cpu_set_t first;
        CPU_ZERO(&first);
        CPU_SET(allowed.front(), &first);
        pthread_setaffinity_np(pthread_self(), sizeof first, &first);
    }
#else
    set_affinity(pin, {});
#endif
    job_ = &job;
    spin_microseconds_.store(spin.count(), std::memory_order_relaxed);
    // Only the threads this run needs are woken; each reads job_ before it reports back, and run()
    // returns only after all of them have, so no thread reads a job_ that a later run has replaced.
    const unsigned helpers = n > 0 ? n - 1 : 0;
    remaining_.store(helpers, std::memory_order_relaxed);
    for (unsigned t = 0; t < helpers; ++t) {
        signals_[t]->generation.fetch_add(1, std::memory_order_release);
        signals_[t]->generation.notify_one();
    }
    if (n > 0) run_job(0);
    for (unsigned left = remaining_.load(std::memory_order_acquire); left != 0;)
        left = wait_for_change(remaining_, left, spin);
    job_ = nullptr;
#ifdef __linux__
    if (pin) pthread_setaffinity_np(pthread_self(), sizeof caller_affinity, &caller_affinity);
#endif
    std::exception_ptr failure;
    {
        std::lock_guard failure_lock(failure_mutex_);
        failure = std::exchange(failure_, nullptr);
    }
    if (failure) std::rethrow_exception(failure);
}

// An exception must not leave a team thread (that would be std::terminate): it becomes the run's.
void WorkerTeam::run_job(unsigned j) {
    t_in_job = true;
    try {
        (*job_)(j);
        t_in_job = false;
    } catch (...) {
        t_in_job = false;
        std::lock_guard lock(failure_mutex_);
        if (!failure_) failure_ = std::current_exception();
    }
}

void WorkerTeam::loop(unsigned t, Signal& signal) {
    // The first wait sleeps at once (no spin) until the thread's first run bumps its signal from 0.
    std::uint64_t seen = 0;
    for (std::chrono::microseconds spin{0};;) {
        seen = wait_for_change(signal.generation, seen, spin);
        if (stopping_) return;
        run_job(t + 1);
        spin = std::chrono::microseconds(spin_microseconds_.load(std::memory_order_relaxed));
        if (remaining_.fetch_sub(1, std::memory_order_acq_rel) == 1) remaining_.notify_one();
    }
}

void WorkerTeam::set_affinity(bool pin, const std::vector<int>& allowed) {
#ifdef __linux__
    // Pinned: thread t (job t + 1) on allowed[t + 1] (modulo their count). Free: every allowed core;
    // a free run after a free run from a thread of the same cores, with no thread started since
    // (which would have the starter's cores, the caller's), changes nothing.
    if (allowed.empty()) return;
    cpu_set_t all;
    CPU_ZERO(&all);
    for (const int c : allowed) CPU_SET(c, &all);
    const bool same_free_set = free_threads_ == threads_.size() && CPU_EQUAL(&all, &free_set_);
    if (!pin && !pinned_ && same_free_set) return;
    for (unsigned t = 0; t < threads_.size(); ++t) {
        cpu_set_t set = all;
        if (pin) {
            CPU_ZERO(&set);
            CPU_SET(allowed[(t + 1) % allowed.size()], &set);
        }
        pthread_setaffinity_np(threads_[t].native_handle(), sizeof set, &set);
    }
    pinned_ = pin;
    free_threads_ = pin ? 0 : threads_.size();
    free_set_ = all;
#else
    (void)pin;
    (void)allowed;
#endif
}

// Never destroyed. A static's destructor would, at exit, wait for a run that another thread is still
// making (a render in a Python daemon thread when the interpreter ends), and that thread, resumed in a
// finalized interpreter, would then be unwound by pthread_exit through pybind11's noexcept GIL guard:
// std::terminate, exit status 134 (found by audit, 2026-12-07). Left alone, the team's threads end with
// the process, as TBB's do.
WorkerTeam& worker_team() {
    static WorkerTeam& team = *new WorkerTeam;
    return team;
}

}  // namespace cellrt::detail
