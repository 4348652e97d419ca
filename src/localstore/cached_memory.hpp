// The memory-access policy of the local-store model: the interface of DirectMemory
// (kernel/traversal.hpp) over a worker's software caches, so that the kd-tree and BIH kernels run
// through the model unchanged. Nodes, leaf index entries (kd: the leaf lists; BIH: the scene index of
// a reordered triangle) go through the node cache, triangles through the triangle cache.
//
// Access modes (the study's section 4.3): synchronous, a node read stalls on a miss; asynchronous,
// touch_node() starts the transfer of a child pair as soon as its parent is read, and a node read is
// the wait, preceded by a re-touch (the line may have been evicted since). Without the re-touch a
// stale wait hands the kernel another line's bytes; the node it decodes is then checked by
// StructureImage::followable(), so that the corrupted traversal still ends and only reads inside the
// arrays (it shows wrong pixels, never crashes).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cellrt/triangle.hpp"
#include "worker_store.hpp"

namespace cellrt::detail {

// Where a structure's arrays lie in the model's main memory, and the facts that make a node safe to follow.
template <class Node>
struct StructureImage {
    static constexpr std::uint8_t kNoDepth = 0xff;

    std::uint64_t nodes = 0, entries = 0, triangles = 0;  // model addresses of the three arrays
    std::uint32_t node_count = 0;
    std::uint64_t leaf_bound = 0;     // a leaf's first + count never exceeds this
    std::uint32_t max_leaf = 0;       // nor its count this (the largest leaf of the structure)
    std::vector<std::uint8_t> depth;  // depth of every node from the root; kNoDepth for padding

    // `n`, read as the node at index `at` from a stale line, when following it is safe; otherwise an
    // empty leaf. Safe: a leaf within the arrays and no larger than the structure's largest, or an
    // inner node whose child pair lies deeper than `at`, so each step of a descent goes deeper and the
    // stack stays within the kernels' bound.
    Node followable(const Node& n, std::uint32_t at) const {
        if (n.is_leaf())
            return n.count() <= max_leaf && std::uint64_t(n.first()) + n.count() <= leaf_bound ? n : Node::leaf(0, 0);
        const std::uint32_t c = n.children();
        const bool deeper = c >= 2 && c % 2 == 0 && c + 1 < node_count && depth[c] != kNoDepth && depth[c] > depth[at];
        return deeper ? n : Node::leaf(0, 0);
    }
};

// Depth of every node reached from the root (nodes[0]); kNoDepth for the others (the padding node).
template <class Node>
std::vector<std::uint8_t> node_depths(std::span<const Node> nodes) {
    std::vector<std::uint8_t> depth(nodes.size(), StructureImage<Node>::kNoDepth);
    std::vector<std::uint32_t> todo{0};
    depth[0] = 0;
    while (!todo.empty()) {
        const std::uint32_t i = todo.back();
        todo.pop_back();
        if (nodes[i].is_leaf()) continue;
        for (std::uint32_t c = nodes[i].children(); c < nodes[i].children() + 2; ++c) {
            depth[c] = static_cast<std::uint8_t>(depth[i] + 1);
            todo.push_back(c);
        }
    }
    return depth;
}

template <class Node>
class CachedMemory {
public:
    CachedMemory(WorkerStore& store, const StructureImage<Node>& image, const LocalStoreConfig& config)
        : store_(store), image_(image),
          wait_(config.access == CacheAccess::sync ? Wait::read : config.retouch ? Wait::retouch : Wait::unchecked) {}

    const Node& node(std::uint32_t i) {
        const std::uint64_t at = image_.nodes + std::uint64_t(i) * sizeof(Node);
        if (wait_ == Wait::unchecked) {
            if (store_.wait_unchecked(store_.node_cache, at, sizeof(Node), &node_)) node_ = image_.followable(node_, i);
        } else {
            store_.read(store_.node_cache, at, sizeof(Node), &node_, wait_ == Wait::retouch ? 2 : 1);
        }
        return node_;
    }
    // The kernels announce a child pair (`i` even: siblings are adjacent) as soon as they read its parent.
    void touch_node(std::uint32_t i) {
        if (wait_ != Wait::read)
            store_.touch(store_.node_cache, image_.nodes + std::uint64_t(i) * sizeof(Node), 2 * sizeof(Node));
    }
    std::uint32_t index(std::uint32_t k) {
        std::uint32_t entry;
        store_.read(store_.node_cache, image_.entries + std::uint64_t(k) * sizeof entry, sizeof entry, &entry);
        return entry;
    }
    const Triangle& triangle(std::uint32_t i) {
        store_.read(store_.triangle_cache, image_.triangles + std::uint64_t(i) * sizeof(Triangle), sizeof(Triangle),
                    &triangle_);
        return triangle_;
    }

private:
    enum class Wait { read, retouch, unchecked };

    WorkerStore& store_;
    const StructureImage<Node>& image_;
    Wait wait_;
    Node node_;
    Triangle triangle_;
};

}  // namespace cellrt::detail
