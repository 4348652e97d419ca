// Buffers that share no cache line with any other allocation: each starts on a line and fills whole
// lines. Per-worker buffers written on every packet are allocated on one thread, one after another;
// with malloc's 16-byte alignment the last line of one worker's buffer may be the first of the
// next worker's, and the two cores then pass that line back and forth on every packet.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace cellrt {

inline constexpr std::size_t kCacheLine = 64;

template <class T>
struct CacheLineAllocator {
    using value_type = T;

    CacheLineAllocator() = default;
    template <class U>
    CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}

    static std::size_t bytes(std::size_t n) { return (n * sizeof(T) + kCacheLine - 1) / kCacheLine * kCacheLine; }
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(bytes(n), std::align_val_t{kCacheLine})); }
    void deallocate(T* p, std::size_t n) noexcept { ::operator delete(p, bytes(n), std::align_val_t{kCacheLine}); }

    template <class U>
    bool operator==(const CacheLineAllocator<U>&) const noexcept {
        return true;
    }
};

template <class T>
using CacheLineVector = std::vector<T, CacheLineAllocator<T>>;

}  // namespace cellrt
