#include "worker_team.hpp"

#include <algorithm>
#include <exception>
#include <thread>

#ifdef __linux__
#include <pthread.h>
#include <sched.h>
#endif

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

}  // namespace

WorkerTeam::~WorkerTeam() {
    {
        std::lock_guard lock(run_mutex_);
        stopping_ = true;
        generation_.fetch_add(1, std::memory_order_release);
        generation_.notify_all();
    }
    for (std::thread& t : threads_) t.join();
}

void WorkerTeam::run(unsigned n, bool pin, std::chrono::microseconds spin, const std::function<void(unsigned)>& job) {
    std::lock_guard lock(run_mutex_);
    while (threads_.size() + 1 < n) {
        // A new thread waits for the next generation, not for any that came before it.
        const auto t = static_cast<unsigned>(threads_.size());
        const std::uint64_t now = generation_.load(std::memory_order_relaxed);
        threads_.emplace_back([this, t, now] { loop(t, now); });
    }
    set_affinity(pin);
#ifdef __linux__
    cpu_set_t caller_affinity;
    if (pin) {
        pthread_getaffinity_np(pthread_self(), sizeof caller_affinity, &caller_affinity);
        cpu_set_t core0;
        CPU_ZERO(&core0);
        CPU_SET(0, &core0);
        pthread_setaffinity_np(pthread_self(), sizeof core0, &core0);
    }
#endif
    job_ = &job;
    jobs_ = n;
    spin_microseconds_.store(spin.count(), std::memory_order_relaxed);
    // Every thread of the team takes part in every run (those beyond n - 1 only report back), so that
    // no thread can still be reading this run's job when the next run writes its own.
    remaining_.store(static_cast<unsigned>(threads_.size()), std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
    generation_.notify_all();
    std::exception_ptr failure;
    try {
        if (n > 0) job(0);
    } catch (...) {
        failure = std::current_exception();
    }
    for (unsigned left = remaining_.load(std::memory_order_acquire); left != 0;)
        left = wait_for_change(remaining_, left, spin);
    job_ = nullptr;
#ifdef __linux__
    if (pin) pthread_setaffinity_np(pthread_self(), sizeof caller_affinity, &caller_affinity);
#endif
    if (failure) std::rethrow_exception(failure);
}

void WorkerTeam::loop(unsigned t, std::uint64_t seen) {
    // A thread's first wait sleeps at once: a new team has run nothing yet.
    for (std::chrono::microseconds spin{0};;) {
        seen = wait_for_change(generation_, seen, spin);
        if (stopping_) return;
        if (t + 1 < jobs_) (*job_)(t + 1);
        spin = std::chrono::microseconds(spin_microseconds_.load(std::memory_order_relaxed));
        if (remaining_.fetch_sub(1, std::memory_order_acq_rel) == 1) remaining_.notify_one();
    }
}

void WorkerTeam::set_affinity(bool pin) {
#ifdef __linux__
    // Pinned: thread t (job t + 1) on core t + 1 (modulo the cores). Free: every core this process may use.
    if (!pin && !pinned_) return;
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    sched_getaffinity(0, sizeof allowed, &allowed);
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    for (unsigned t = 0; t < threads_.size(); ++t) {
        cpu_set_t set = allowed;
        if (pin) {
            CPU_ZERO(&set);
            CPU_SET((t + 1) % cores, &set);
        }
        pthread_setaffinity_np(threads_[t].native_handle(), sizeof set, &set);
    }
    pinned_ = pin;
#else
    (void)pin;
#endif
}

WorkerTeam& worker_team() {
    static WorkerTeam team;
    return team;
}

}  // namespace cellrt::detail
