// Deterministic parallel tree layout, shared by the kd-tree and BIH builders.
//
// A builder splits large nodes into two tasks; each task builds its subtree into a Subtree of its
// own, numbered from 0. flatten() then lays the pieces out depth-first with the two children of
// every inner node adjacent (a pair starting at an even index), which is exactly the layout a
// single-threaded build produces. So the final bytes depend only on the tree, never on which thread
// built what or how the work was cut.
//
// Node requirements: is_leaf(), children() (inner: index of the child pair), first() (leaf: first
// entry of its index list) and with_index(i) (a copy whose child pair or first entry is i).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "cellrt/error.hpp"

namespace cellrt::detail {

template <class Node>
struct Subtree {
    // nodes[0] is the root; child pairs follow in local numbering. When the root's children were
    // built as tasks of their own, `left` and `right` hold them and `nodes` holds only the root.
    std::vector<Node> nodes;
    // Leaf index lists in local numbering (structures whose leaves index a shared array leave it empty).
    std::vector<std::uint32_t> indices;
    std::unique_ptr<Subtree> left, right;
    double cost = 0.0;  // the builder's estimate, for retraction
};

// Threads a build may use: the user's count (0: all), never more than the machine has.
inline int build_concurrency(unsigned requested) {
    const int cores = tbb::info::default_concurrency();
    return requested == 0 ? cores : static_cast<int>(std::min(static_cast<unsigned>(cores), requested));
}

// Checks an index against the `max` a node can encode; throws naming the structure otherwise.
inline std::uint32_t checked_node_index(std::size_t i, std::uint32_t max, const char* structure) {
    if (i > max)
        throw Error(std::string(structure) + ": more nodes or leaf references than its node format can address; "
                                             "the scene is too large (lower max_depth)");
    return static_cast<std::uint32_t>(i);
}

// The nodes and leaf index entries `s` lays out, its pieces together.
template <class Node>
std::pair<std::size_t, std::size_t> laid_out_size(const Subtree<Node>& s) {
    if (!s.left) return {s.nodes.size() - 1, s.indices.size()};
    const auto [ln, li] = laid_out_size(*s.left);
    const auto [rn, ri] = laid_out_size(*s.right);
    return {2 + ln + rn, li + ri};
}

// Appends the subtree `s` whose root goes to nodes[slot] (already allocated).
template <class Node>
void flatten_pieces(const Subtree<Node>& s, std::uint32_t slot, std::vector<Node>& nodes,
                    std::vector<std::uint32_t>& indices, std::uint32_t max_index, const char* structure) {
    if (s.left) {
        const auto pair = checked_node_index(nodes.size() + 1, max_index, structure) - 1;
        nodes.resize(nodes.size() + 2);
        nodes[slot] = s.nodes[0].with_index(pair);
        flatten_pieces(*s.left, pair, nodes, indices, max_index, structure);
        flatten_pieces(*s.right, pair + 1, nodes, indices, max_index, structure);
        return;
    }
    const auto base = static_cast<std::uint32_t>(nodes.size());
    const auto first_index = static_cast<std::uint32_t>(indices.size());
    indices.insert(indices.end(), s.indices.begin(), s.indices.end());
    checked_node_index(indices.size(), max_index, structure);
    checked_node_index(nodes.size() + s.nodes.size(), max_index, structure);
    auto place = [&](std::uint32_t local) { return local == 0 ? slot : base + local - 1; };
    nodes.resize(nodes.size() + s.nodes.size() - 1);
    for (std::uint32_t i = 0; i < s.nodes.size(); ++i) {
        const Node& n = s.nodes[i];
        nodes[place(i)] = n.is_leaf() ? n.with_index(first_index + n.first()) : n.with_index(place(n.children()));
    }
}

// Where flatten_pieces puts a piece without children of its own: its root's slot, its other nodes
// from `base` on and its index entries from `first_index` on.
template <class Node>
struct PiecePlace {
    const Subtree<Node>* piece;
    std::uint32_t slot;
    std::size_t base, first_index;
};

// flatten_pieces' layout without its copies: each inner piece's pair (written), and where each other
// piece goes, in the order flatten_pieces meets them; the same index checks, against the same sizes.
template <class Node>
void plan_pieces(const Subtree<Node>& s, std::uint32_t slot, std::vector<Node>& nodes, std::size_t& next_node,
                 std::size_t& next_index, std::vector<PiecePlace<Node>>& places, std::uint32_t max_index,
                 const char* structure) {
    if (s.left) {
        const auto pair = checked_node_index(next_node + 1, max_index, structure) - 1;
        next_node += 2;
        nodes[slot] = s.nodes[0].with_index(pair);
        plan_pieces(*s.left, pair, nodes, next_node, next_index, places, max_index, structure);
        plan_pieces(*s.right, pair + 1, nodes, next_node, next_index, places, max_index, structure);
        return;
    }
    places.push_back({&s, slot, next_node, next_index});
    next_index += s.indices.size();
    checked_node_index(next_index, max_index, structure);
    checked_node_index(next_node + s.nodes.size(), max_index, structure);
    next_node += s.nodes.size() - 1;
}

// Lays `s` out into `nodes` (whose element `slot` is its root's place) and `indices`. Their room is
// taken at once: a parallel build's many pieces would otherwise grow them piece by piece, copying
// and faulting in fresh pages each time (0.8 ms on one thread, 2.1 on two for Sibenik's BIH). With
// `parallel` (a parallel build, called within its arena) the pieces are copied on its threads: each
// piece's place follows from the sizes of those before it in depth-first order, so the bytes are
// those of the one-thread layout, and the layout no longer runs on one thread after a build whose
// tree did not.
template <class Node>
void flatten(const Subtree<Node>& s, std::uint32_t slot, std::vector<Node>& nodes, std::vector<std::uint32_t>& indices,
             std::uint32_t max_index, const char* structure, bool parallel = false) {
    const auto [more_nodes, more_indices] = laid_out_size(s);
    if (!parallel || !s.left) {
        nodes.reserve(nodes.size() + more_nodes);
        indices.reserve(indices.size() + more_indices);
        flatten_pieces(s, slot, nodes, indices, max_index, structure);
        return;
    }
    std::size_t next_node = nodes.size(), next_index = indices.size();
    nodes.resize(nodes.size() + more_nodes);
    indices.resize(indices.size() + more_indices);
    std::vector<PiecePlace<Node>> places;
    plan_pieces(s, slot, nodes, next_node, next_index, places, max_index, structure);
    tbb::parallel_for(std::size_t{0}, places.size(), [&](std::size_t p) {
        const PiecePlace<Node>& at = places[p];
        const Subtree<Node>& piece = *at.piece;
        std::copy(piece.indices.begin(), piece.indices.end(), indices.begin() + static_cast<std::ptrdiff_t>(at.first_index));
        auto place = [&](std::uint32_t local) {
            return local == 0 ? at.slot : static_cast<std::uint32_t>(at.base + local - 1);
        };
        for (std::uint32_t i = 0; i < piece.nodes.size(); ++i) {
            const Node& n = piece.nodes[i];
            nodes[place(i)] = n.is_leaf() ? n.with_index(static_cast<std::uint32_t>(at.first_index) + n.first())
                                          : n.with_index(place(n.children()));
        }
    });
}

}  // namespace cellrt::detail
