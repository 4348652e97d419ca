// Memory mode (b) of the CUDA backend (docs/GPU.md): the study's software caches (Hapala, section
// 4.3; the local-store model's SoftwareCache, localstore/software_cache.hpp) in an array the caller
// gives: a block's shared memory on the GPU, a plain array on the host, where tests hold it to the
// model's counts. A cache maps lines of the tree's address space (CacheAddressMap) by set (line
// number mod sets) and tag, direct-mapped or in the least recently used of 4 ways, as the model does,
// so that one thread reading one ray after another counts exactly the model's hits, misses and
// evictions for the same reads (tests/test_shared_cache.cpp). Access is synchronous (a miss copies
// its line in before the read returns) or asynchronous, the study's touch then wait (its section
// 4.3): touch() claims the slots of a child pair's lines and starts their copies (`cp.async` on the
// GPU, the SPE's DMA get), and the thread's next read first waits for them (complete()), looking the
// line up again as it reads (the study's re-touch: the wait trusts no slot its touch chose).
//
// Sharing (the choice, and why). On the Cell a cache belonged to one SPE tracing one ray at a time;
// on the GPU the 128 threads of a block share the block's caches, which is what makes them pay:
// coherent rays of one block read the same top of the tree (Aila & Laine 2009, section 2, on the
// coherence of a warp's rays). Locks per line would serialise the warps on every read, and per-warp
// partitions would only quarter the lines without removing the race (the lanes of one warp diverge
// and run independently since Volta). But the tree and the triangles never change during a trace, so a
// line's bytes are a function of its tag, and a reader needs only to know that the slot it copied
// from held its line for the whole copy: each slot has a sequence number (a seqlock, Lameter 2005;
// Boehm, "Can seqlocks get along with programming language memory models?", MSPC 2012), odd while a
// writer fills it. A reader reads the number, the tag, the bytes, the number again; a changed number
// means the copy may be torn and the read goes to global memory instead (`torn`). A writer claims a
// slot by compare-and-swap from an even number to the next odd one and releases it at the next even
// one; a writer that loses the race reads global memory (`unfilled`). The LRU stamps are updated
// without ordering: a lost or late stamp only changes which way a later miss evicts, never a byte
// read. Two threads missing the same line at once may fill it into two ways of its set; both copies
// are right, one is wasted. On the host, one thread per cache, none of this ever fires.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "cellrt/device.hpp"
#include "cellrt/host_device.hpp"
#include "cellrt/triangle.hpp"
#include "kernel/traversal.hpp"

namespace cellrt::detail {

// One cache's geometry: line size, sets and ways (1: direct-mapped; 4: 4-way with LRU), as the
// model's CacheLayout. Validated on the host (device_memory.hpp).
struct SharedCacheLayout {
    std::uint32_t line_bytes = 128;
    std::uint32_t sets = 128;
    std::uint32_t ways = 1;

    // Per line, besides its bytes: its tag (line number, kEmpty when none), sequence number and LRU stamp.
    static constexpr std::uint32_t kDirectoryBytesPerLine = 12;

    CELLRT_HD std::uint32_t lines() const { return sets * ways; }
    // The array a cache needs: the lines' bytes, their directory and the LRU clock, rounded up to 16
    // bytes so that a second cache after it starts 16-byte aligned, as the lines need.
    CELLRT_HD std::size_t bytes() const {
        const std::size_t raw = std::size_t(lines()) * (line_bytes + kDirectoryBytesPerLine) + sizeof(std::uint32_t);
        return (raw + 15) / 16 * 16;
    }
};

// Where the tree's three arrays (nodes, leaf entries, triangles) lie in the caches' address space:
// each at a 4 KiB aligned address of its own, as in the local-store model's main memory
// (localstore/main_memory.hpp), so sets and conflicts, and so the counts, are the model's; a line
// (at most 4 KiB) never spans two arrays, and its bytes past its array's end read as zero.
struct CacheAddressMap {
    static constexpr std::uint64_t kAlign = 4096;
    static constexpr int kNodes = 0, kEntries = 1, kTriangles = 2;

    const std::byte* data[3];
    std::uint64_t base[3];
    std::uint64_t bytes[3];
    std::uint64_t end;  // past the last array: every address read is below it

    // The bytes at `address` in array `region`, which holds it.
    CELLRT_HD const std::byte* at(int region, std::uint64_t address) const { return data[region] + (address - base[region]); }
    CELLRT_HD int region_of(std::uint64_t address) const {
        return address >= base[kTriangles] ? kTriangles : address >= base[kEntries] ? kEntries : kNodes;
    }
};

template <class Traits>
CELLRT_HD CacheAddressMap cache_address_map(const TreeView<Traits>& view, std::size_t nodes, std::size_t entries,
                                            std::size_t triangles) {
    CacheAddressMap m;
    m.data[0] = reinterpret_cast<const std::byte*>(view.nodes);
    m.data[1] = reinterpret_cast<const std::byte*>(view.entries);
    m.data[2] = reinterpret_cast<const std::byte*>(view.triangles);
    m.bytes[0] = nodes * sizeof(typename Traits::Node);
    m.bytes[1] = entries * sizeof(std::uint32_t);
    m.bytes[2] = triangles * sizeof(Triangle);
    std::uint64_t next = CacheAddressMap::kAlign;  // address 0 stays unmapped, as in the model
    for (int r = 0; r < 3; ++r) {
        m.base[r] = next;
        const std::uint64_t rounded = (m.bytes[r] + CacheAddressMap::kAlign - 1) / CacheAddressMap::kAlign * CacheAddressMap::kAlign;
        next += rounded > CacheAddressMap::kAlign ? rounded : CacheAddressMap::kAlign;
    }
    m.end = next;
    return m;
}

// The few memory operations the seqlock needs: ordered within the block on the device, plain on the
// host (one thread per cache).
#if defined(__CUDA_ARCH__)
__device__ inline std::uint32_t global_word(const std::byte* p) { return *reinterpret_cast<const std::uint32_t*>(p); }
__device__ inline std::uint32_t shared_load(const std::uint32_t* p) { return *static_cast<const volatile std::uint32_t*>(p); }
__device__ inline void shared_store(std::uint32_t* p, std::uint32_t v) { *static_cast<volatile std::uint32_t*>(p) = v; }
__device__ inline void block_fence() { __threadfence_block(); }
__device__ inline bool claim(std::uint32_t* seq, std::uint32_t even) { return atomicCAS(seq, even, even + 1) == even; }
__device__ inline std::uint32_t tick(std::uint32_t* clock) { return atomicAdd(clock, 1u) + 1u; }
#else
inline std::uint32_t global_word(const std::byte* p) {
    std::uint32_t w;
    std::memcpy(&w, p, sizeof w);
    return w;
}
inline std::uint32_t shared_load(const std::uint32_t* p) { return *p; }
inline void shared_store(std::uint32_t* p, std::uint32_t v) { *p = v; }
inline void block_fence() {}
inline bool claim(std::uint32_t* seq, std::uint32_t even) {
    if (*seq != even) return false;
    *seq = even + 1;
    return true;
}
inline std::uint32_t tick(std::uint32_t* clock) { return ++*clock; }
#endif

// Asynchronous access: the line fills one thread has started and not yet waited for. On the GPU their
// copies are the thread's cp.async groups; on the host they are made at the wait, so that a read that
// did not wait would read the slot's old bytes (and fail the tests). A filling slot's sequence number
// stays odd until the wait, so other threads never read it half-filled.
struct AsyncFills {
    // A child pair spans at most three lines (two 12-byte BIH nodes over 16-byte lines); a full list
    // is waited for before it grows.
    static constexpr int kMax = 4;
    std::uint32_t slot[kMax];
    std::uint32_t seq[kMax];   // the slot's even sequence number before the fill claimed it
    std::uint64_t line[kMax];  // the line's address, for the host's copy
    int count = 0;
};

#if defined(__CUDA_ARCH__)
// Starts the copy of 16 bytes into shared memory, of which the first `from_bytes` (0 to 16) come from
// `from` and the rest are zeros (cp.async's source size); cp.async.ca: through L1.
__device__ inline void copy_16_async(std::uint32_t* to, const std::byte* from, std::uint32_t from_bytes) {
    const auto shared = static_cast<std::uint32_t>(__cvta_generic_to_shared(to));
    asm volatile("cp.async.ca.shared.global [%0], [%1], 16, %2;\n" ::"r"(shared), "l"(from), "r"(from_bytes) : "memory");
}
__device__ inline void commit_async() { asm volatile("cp.async.commit_group;\n" ::: "memory"); }
__device__ inline void wait_async() { asm volatile("cp.async.wait_all;\n" ::: "memory"); }
#endif

// One software cache over `storage` (layout.bytes() bytes, 16-byte aligned). A view: copies share the cache.
class SharedCache {
public:
    static constexpr std::uint32_t kEmpty = ~0u;

    CELLRT_HD SharedCache(std::byte* storage, const SharedCacheLayout& layout)
        : data_(reinterpret_cast<std::uint32_t*>(storage)),
          tags_(data_ + std::size_t(layout.lines()) * layout.line_bytes / 4),
          seqs_(tags_ + layout.lines()),
          stamps_(seqs_ + layout.lines()),
          clock_(stamps_ + layout.lines()),
          line_bytes_(layout.line_bytes),
          sets_(layout.sets),
          ways_(layout.ways),
          line_shift_(0) {
        while ((1u << line_shift_) < line_bytes_) ++line_shift_;
    }

    // Empties the cache: thread `thread` of `threads` clears its share of the directory (the block
    // synchronises before any read).
    CELLRT_HD void clear(unsigned thread, unsigned threads) const {
        for (std::uint32_t s = thread; s < sets_ * ways_; s += threads) {
            tags_[s] = kEmpty;
            seqs_[s] = 0;
            stamps_[s] = 0;
        }
        if (thread == 0) *clock_ = 0;
    }

    // Reads `size` bytes at `address` (4-byte aligned, a multiple of 4, within one array of `map`)
    // into `words`, line by line, counting each line's lookup in `c`.
    CELLRT_HD void read(const CacheAddressMap& map, std::uint64_t address, std::uint32_t size, std::uint32_t* words,
                        DeviceCacheCounts& c) const {
        const std::uint64_t end = address + size;
        for (std::uint64_t line = address & ~std::uint64_t(line_bytes_ - 1); line < end; line += line_bytes_) {
            const std::uint32_t tag = static_cast<std::uint32_t>(line >> line_shift_);
            const std::uint32_t first = (tag & (sets_ - 1)) * ways_;
            std::uint32_t s = first;
            for (; s < first + ways_; ++s) {
                const std::uint32_t seq = shared_load(&seqs_[s]);
                block_fence();
                if ((seq & 1u) || shared_load(&tags_[s]) != tag) continue;
                copy_piece(line_data(s), line, address, size, words);
                block_fence();
                if (shared_load(&seqs_[s]) == seq) {
                    ++c.hits;
                    stamps_[s] = tick(clock_);
                } else {
                    ++c.torn;
                    copy_global(map, line, address, size, words);
                }
                break;
            }
            if (s < first + ways_) continue;
            ++c.misses;
            fill(map, line, tag, first, address, size, words, c);
        }
    }

    // The asynchronous touch of [address, address + size) (within one array of `map`): a line in the
    // cache counts a touch hit and is marked used; a missing one is placed as a miss would place it
    // and its copy started (a prefetch), to complete at complete(fills). A slot another thread is
    // filling is left to it (the touch is a hint; the read will look again). The thread's earlier
    // fills are completed first, so a line is never in flight twice.
    CELLRT_HD void touch(const CacheAddressMap& map, std::uint64_t address, std::uint32_t size, AsyncFills& fills,
                         DeviceCacheCounts& c) const {
        complete(map, fills);
        const std::uint64_t end = address + size;
        for (std::uint64_t line = address & ~std::uint64_t(line_bytes_ - 1); line < end; line += line_bytes_) {
            const std::uint32_t tag = static_cast<std::uint32_t>(line >> line_shift_);
            const std::uint32_t first = (tag & (sets_ - 1)) * ways_;
            std::uint32_t s = first;
            while (s < first + ways_ && ((shared_load(&seqs_[s]) & 1u) || shared_load(&tags_[s]) != tag)) ++s;
            if (s < first + ways_) {
                ++c.touch_hits;
                stamps_[s] = tick(clock_);
                continue;
            }
            if (fills.count == AsyncFills::kMax) complete(map, fills);
            const std::uint32_t victim = victim_in(first);
            const std::uint32_t seq = shared_load(&seqs_[victim]);
            if ((seq & 1u) || !claim(&seqs_[victim], seq)) continue;
            ++c.prefetches;
            block_fence();
            if (shared_load(&tags_[victim]) != kEmpty) ++c.evictions;
            shared_store(&tags_[victim], tag);
            stamps_[victim] = tick(clock_);
#if defined(__CUDA_ARCH__)
            const int region = map.region_of(line);
            const std::uint64_t stop = map.base[region] + map.bytes[region];
            const std::byte* from = map.at(region, line);
            std::uint32_t* bytes = line_data(victim);
            for (std::uint32_t k = 0; k < line_bytes_ / 16; ++k) {
                const std::uint64_t at = line + 16 * k;
                const std::uint32_t n = at >= stop ? 0u : stop - at >= 16 ? 16u : static_cast<std::uint32_t>(stop - at);
                copy_16_async(bytes + 4 * k, n ? from + 16 * k : from, n);
            }
            commit_async();
#endif
            fills.slot[fills.count] = victim;
            fills.seq[fills.count] = seq;
            fills.line[fills.count] = line;
            ++fills.count;
        }
    }

    // The wait: the thread's started fills complete (their copies arrive; on the host, are made) and
    // are published, their slots readable by every thread.
    CELLRT_HD void complete(const CacheAddressMap& map, AsyncFills& fills) const {
        if (fills.count == 0) return;
#if defined(__CUDA_ARCH__)
        static_cast<void>(map);
        wait_async();
#else
        for (int k = 0; k < fills.count; ++k) copy_line(map, fills.line[k], line_data(fills.slot[k]));
#endif
        block_fence();
        for (int k = 0; k < fills.count; ++k) shared_store(&seqs_[fills.slot[k]], fills.seq[k] + 2);
        fills.count = 0;
    }

private:
    // Where a missing line of the set starting at slot `first` goes: an empty way, else the least
    // recently used one (the only one when direct-mapped), as SoftwareCache::place chooses.
    CELLRT_HD std::uint32_t victim_in(std::uint32_t first) const {
        std::uint32_t victim = first;
        for (std::uint32_t s = first; s < first + ways_; ++s) {
            if (shared_load(&tags_[s]) == kEmpty) return s;
            if (stamps_[s] < stamps_[victim]) victim = s;
        }
        return victim;
    }

    // A read's miss: the line is placed, filled at once, and the piece read from it.
    CELLRT_HD void fill(const CacheAddressMap& map, std::uint64_t line, std::uint32_t tag, std::uint32_t first,
                        std::uint64_t address, std::uint32_t size, std::uint32_t* words, DeviceCacheCounts& c) const {
        const std::uint32_t victim = victim_in(first);
        const std::uint32_t seq = shared_load(&seqs_[victim]);
        if ((seq & 1u) || !claim(&seqs_[victim], seq)) {
            ++c.unfilled;
            copy_global(map, line, address, size, words);
            return;
        }
        block_fence();
        if (shared_load(&tags_[victim]) != kEmpty) ++c.evictions;
        shared_store(&tags_[victim], tag);
        std::uint32_t* bytes = line_data(victim);
        copy_line(map, line, bytes);
        copy_piece(bytes, line, address, size, words);
        stamps_[victim] = tick(clock_);
        block_fence();
        shared_store(&seqs_[victim], seq + 2);
    }

    // The line's bytes from the tree's arrays into `bytes`, zeros past its array's end.
    CELLRT_HD void copy_line(const CacheAddressMap& map, std::uint64_t line, std::uint32_t* bytes) const {
        const int region = map.region_of(line);
        const std::uint64_t stop = map.base[region] + map.bytes[region];
        const std::byte* from = map.at(region, line);
        for (std::uint32_t w = 0; w < line_bytes_ / 4; ++w) bytes[w] = line + 4 * w < stop ? global_word(from + 4 * w) : 0u;
    }

    CELLRT_HD std::uint32_t* line_data(std::uint32_t slot) const { return data_ + std::size_t(slot) * (line_bytes_ / 4); }
    // Copies the words of [address, address + size) that lie in the line starting at `line` (whose
    // bytes `from` points at) into `words` (the object at `address`).
    CELLRT_HD void copy_piece(const std::uint32_t* from, std::uint64_t line, std::uint64_t address, std::uint32_t size,
                              std::uint32_t* words) const {
        const std::uint64_t lo = address > line ? address : line;
        const std::uint64_t hi = address + size < line + line_bytes_ ? address + size : line + line_bytes_;
        for (std::uint64_t a = lo; a < hi; a += 4) words[(a - address) / 4] = shared_load(&from[(a - line) / 4]);
    }
    // The same piece read from global memory (the tree's own arrays), past the cache.
    CELLRT_HD void copy_global(const CacheAddressMap& map, std::uint64_t line, std::uint64_t address, std::uint32_t size,
                               std::uint32_t* words) const {
        const std::uint64_t lo = address > line ? address : line;
        const std::uint64_t hi = address + size < line + line_bytes_ ? address + size : line + line_bytes_;
        const int region = map.region_of(address);
        for (std::uint64_t a = lo; a < hi; a += 4) words[(a - address) / 4] = global_word(map.at(region, a));
    }

    std::uint32_t* data_;
    std::uint32_t* tags_;
    std::uint32_t* seqs_;
    std::uint32_t* stamps_;
    std::uint32_t* clock_;
    std::uint32_t line_bytes_, sets_, ways_, line_shift_;
};

// The memory policy of mode (b): DirectMemory's interface (kernel/traversal.hpp) through a node cache
// (nodes and leaf entries, as the model's CachedMemory) and a triangle cache, so the trees' kernels
// run through it unchanged. One per thread; the caches are the block's. Synchronous, or with `async`
// the study's asynchronous access: touch_node() starts the fills of a child pair's lines as soon as
// the kernel reads their parent, and the next read of the node cache waits for them (with its
// re-touch: the line is looked up again).
template <class Node>
class SharedCacheMemory {
public:
    CELLRT_HD SharedCacheMemory(const SharedCache& node_cache, const SharedCache& triangle_cache,
                                const CacheAddressMap& map, bool async = false)
        : node_cache_(node_cache), triangle_cache_(triangle_cache), map_(map), async_(async) {}
    // A fill still in flight is published before the thread leaves (another thread may want its slot).
    CELLRT_HD ~SharedCacheMemory() { node_cache_.complete(map_, fills_); }
    SharedCacheMemory(const SharedCacheMemory&) = delete;
    SharedCacheMemory& operator=(const SharedCacheMemory&) = delete;

    CELLRT_HD const Node& node(std::uint32_t i) {
        node_cache_.complete(map_, fills_);
        std::uint32_t words[sizeof(Node) / 4];
        node_cache_.read(map_, map_.base[CacheAddressMap::kNodes] + std::uint64_t(i) * sizeof(Node), sizeof(Node), words,
                         node_counts);
        std::memcpy(&node_, words, sizeof(Node));
        return node_;
    }
    // The kernels announce a child pair (siblings are adjacent) as soon as they read its parent.
    CELLRT_HD void touch_node(std::uint32_t i) {
        if (async_)
            node_cache_.touch(map_, map_.base[CacheAddressMap::kNodes] + std::uint64_t(i) * sizeof(Node), 2 * sizeof(Node),
                              fills_, node_counts);
    }
    CELLRT_HD std::uint32_t index(std::uint32_t k) {
        node_cache_.complete(map_, fills_);
        std::uint32_t entry;
        node_cache_.read(map_, map_.base[CacheAddressMap::kEntries] + std::uint64_t(k) * sizeof entry, sizeof entry,
                         &entry, node_counts);
        return entry;
    }
    CELLRT_HD const Triangle& triangle(std::uint32_t i) {
        std::uint32_t words[sizeof(Triangle) / 4];
        triangle_cache_.read(map_, map_.base[CacheAddressMap::kTriangles] + std::uint64_t(i) * sizeof(Triangle),
                             sizeof(Triangle), words, triangle_counts);
        std::memcpy(&triangle_, words, sizeof(Triangle));
        return triangle_;
    }

    DeviceCacheCounts node_counts, triangle_counts;  // this thread's lookups

private:
    static_assert(sizeof(Node) % 4 == 0 && sizeof(Triangle) % 4 == 0, "the caches copy whole 32-bit words");
    SharedCache node_cache_, triangle_cache_;
    CacheAddressMap map_;
    bool async_;
    AsyncFills fills_;  // the node cache's fills this thread started and has not waited for
    Node node_;
    Triangle triangle_;
};

}  // namespace cellrt::detail
