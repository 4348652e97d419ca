// A fixed-size array that is zero when made, without being written: an image's pixels. A
// std::vector writes its zeros on the thread that makes it: a 1080p frame's 25 MB of floats, some 10
// ms on one core before the render's workers start, and page faults on every 4 KiB of it. Here the
// memory comes zero from the kernel, untouched: a large block mapped on its own and asked for in
// 2 MiB pages (madvise(MADV_HUGEPAGE), 13 faults for that frame where the kernel's transparent huge
// pages are on; 4 KiB pages where they are off), a small one from calloc. The pages are then first
// touched by whoever writes the elements: a frame's by the render's workers, in parallel
// (docs/SCALING.md, "The frame's memory").
//
// The size is fixed (no resize, no push_back): elements of a resized vector would be made in memory
// that held others, which is not zero. T is trivially copyable and its value-initialised state is all
// bits zero (Vec3, whose zero floats are +0, and bytes).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <memory>
#include <type_traits>
#include <utility>

namespace cellrt {
namespace detail {

// `bytes` of zero memory (at least one), and how to give it back; throws std::bad_alloc.
struct ZeroedBlock {
    void* data;
    std::size_t mapped;  // the length of its own mapping, 0 for a block from calloc
};
ZeroedBlock allocate_zeroed(std::size_t bytes);
void release_zeroed(void* data, std::size_t mapped) noexcept;

}  // namespace detail

template <class T>
class ZeroedArray {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                  "ZeroedArray holds trivially copyable elements whose zero is all bits zero");
    static_assert(alignof(T) <= alignof(std::max_align_t), "calloc aligns for max_align_t only");

public:
    using value_type = T;
    using iterator = T*;
    using const_iterator = const T*;

    ZeroedArray() = default;
    // n elements, each T{} (all bits zero), none of them written.
    explicit ZeroedArray(std::size_t n) : data_(make(n)), size_(n) {}
    ZeroedArray(const ZeroedArray& o) : data_(make(o.size_)), size_(o.size_) {
        if (size_) std::memcpy(data(), o.data(), size_ * sizeof(T));
    }
    ZeroedArray(ZeroedArray&& o) noexcept : data_(std::move(o.data_)), size_(std::exchange(o.size_, 0)) {}
    ZeroedArray& operator=(const ZeroedArray& o) {
        if (this != &o) *this = ZeroedArray(o);
        return *this;
    }
    ZeroedArray& operator=(ZeroedArray&& o) noexcept {
        data_ = std::move(o.data_);
        size_ = std::exchange(o.size_, 0);
        return *this;
    }
    ~ZeroedArray() = default;

    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    T* data() { return data_.get(); }
    const T* data() const { return data_.get(); }
    T& operator[](std::size_t i) { return data()[i]; }
    const T& operator[](std::size_t i) const { return data()[i]; }
    T* begin() { return data(); }
    T* end() { return data() + size_; }
    const T* begin() const { return data(); }
    const T* end() const { return data() + size_; }

    friend bool operator==(const ZeroedArray& a, const ZeroedArray& b) {
        return a.size_ == b.size_ && std::equal(a.begin(), a.end(), b.begin());
    }

private:
    struct Release {
        std::size_t mapped = 0;
        void operator()(T* p) const noexcept { detail::release_zeroed(p, mapped); }
    };
    using Owner = std::unique_ptr<T, Release>;

    static Owner make(std::size_t n) {
        if (n == 0) return Owner();
        if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_alloc();
        const detail::ZeroedBlock b = detail::allocate_zeroed(n * sizeof(T));
        // The kernel's or calloc's zero bytes are T's objects (implicit-lifetime, C++20 [intro.object]).
        return Owner(static_cast<T*>(b.data), Release{b.mapped});
    }

    Owner data_;
    std::size_t size_ = 0;
};

}  // namespace cellrt
