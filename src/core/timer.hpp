// Stopwatch for build and render times: wall clock, and the process's CPU time (every thread's), which
// a busy shared machine disturbs less.
#pragma once

#include <chrono>
#include <ctime>

namespace cellrt {

class Timer {
public:
    Timer() : start_(std::chrono::steady_clock::now()), cpu_start_(std::clock()) {}
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    double cpu_seconds() const { return static_cast<double>(std::clock() - cpu_start_) / CLOCKS_PER_SEC; }

private:
    std::chrono::steady_clock::time_point start_;
    std::clock_t cpu_start_;
};

}  // namespace cellrt
