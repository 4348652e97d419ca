#include "worker_team.hpp"

#include <algorithm>

#ifdef __linux__
#include <pthread.h>
#include <sched.h>
#endif

namespace cellrt::detail {

WorkerTeam::~WorkerTeam() {
    {
        std::lock_guard lock(run_mutex_);
        stopping_ = true;
        generation_.fetch_add(1, std::memory_order_release);
        generation_.notify_all();
    }
    for (std::thread& t : threads_) t.join();
}

void WorkerTeam::run(unsigned n, bool pin, const std::function<void(unsigned)>& job,
                     const std::function<void()>& meanwhile) {
    std::lock_guard lock(run_mutex_);
    while (threads_.size() < n) {
        // A new thread waits for the next generation, not for any that came before it.
        const auto w = static_cast<unsigned>(threads_.size());
        const std::uint64_t now = generation_.load(std::memory_order_relaxed);
        threads_.emplace_back([this, w, now] { loop(w, now); });
    }
    set_affinity(pin);
    job_ = &job;
    active_ = n;
    // Every thread of the team takes part in every run (those beyond n only report back), so that
    // no thread can still be reading this run's job when the next run writes its own.
    remaining_.store(static_cast<unsigned>(threads_.size()), std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
    generation_.notify_all();
    if (meanwhile) meanwhile();
    for (unsigned left = remaining_.load(std::memory_order_acquire); left != 0;
         left = remaining_.load(std::memory_order_acquire))
        remaining_.wait(left, std::memory_order_acquire);
    job_ = nullptr;
}

void WorkerTeam::loop(unsigned w, std::uint64_t seen) {
    for (;;) {
        generation_.wait(seen, std::memory_order_acquire);
        seen = generation_.load(std::memory_order_acquire);
        if (stopping_) return;
        if (w < active_) (*job_)(w);
        if (remaining_.fetch_sub(1, std::memory_order_acq_rel) == 1) remaining_.notify_one();
    }
}

void WorkerTeam::set_affinity(bool pin) {
#ifdef __linux__
    // Pinned: thread w on core w (modulo the cores). Free: every core this process may use.
    if (!pin && !pinned_) return;
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    sched_getaffinity(0, sizeof allowed, &allowed);
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    for (unsigned w = 0; w < threads_.size(); ++w) {
        cpu_set_t set = allowed;
        if (pin) {
            CPU_ZERO(&set);
            CPU_SET(w % cores, &set);
        }
        pthread_setaffinity_np(threads_[w].native_handle(), sizeof set, &set);
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
