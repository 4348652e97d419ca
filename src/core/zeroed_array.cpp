#include "cellrt/zeroed_array.hpp"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <new>

namespace cellrt::detail {
namespace {

// Blocks from this size are mapped on their own, in whole 2 MiB pages (a transparent huge page's
// size on x86-64 and arm64): at most a page beyond a frame of 4 MiB or more.
constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kMapFrom = std::size_t{4} << 20;

// AddressSanitizer's allocator puts red zones around a block; a mapping of its own would have none
// (and up to 2 MiB of slack past its end), so under it every block comes from calloc (GCC defines
// __SANITIZE_ADDRESS__, clang answers __has_feature).
#if !defined(__has_feature)
#define CELLRT_HAS_FEATURE(x) 0
#else
#define CELLRT_HAS_FEATURE(x) __has_feature(x)
#endif
#if defined(__SANITIZE_ADDRESS__) || CELLRT_HAS_FEATURE(address_sanitizer)
constexpr bool kOwnMappings = false;
#else
constexpr bool kOwnMappings = true;
#endif
#undef CELLRT_HAS_FEATURE

}  // namespace

ZeroedBlock allocate_zeroed(std::size_t bytes) {
    if (bytes < kMapFrom || !kOwnMappings) {
        void* p = std::calloc(bytes, 1);
        if (!p) throw std::bad_alloc();
        return {p, 0};
    }
    if (bytes > static_cast<std::size_t>(-1) - 2 * kHugePage) throw std::bad_alloc();
    const std::size_t length = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    // A page more than asked, so that a 2 MiB boundary starts the block; the ends around it go back.
    const std::size_t over = length + kHugePage;
    void* const raw = ::mmap(nullptr, over, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const auto base = reinterpret_cast<std::uintptr_t>(raw);
    const std::uintptr_t start = (base + kHugePage - 1) / kHugePage * kHugePage;
    if (start > base) ::munmap(raw, start - base);
    if (const std::uintptr_t tail = base + over - (start + length); tail > 0)
        ::munmap(reinterpret_cast<void*>(start + length), tail);
#ifdef MADV_HUGEPAGE
    // Only advice: where the kernel's huge pages are off ("never") the block takes 4 KiB pages.
    ::madvise(reinterpret_cast<void*>(start), length, MADV_HUGEPAGE);
#endif
    return {reinterpret_cast<void*>(start), length};
}

void release_zeroed(void* data, std::size_t mapped) noexcept {
    if (mapped) ::munmap(data, mapped);
    else std::free(data);
}

}  // namespace cellrt::detail
