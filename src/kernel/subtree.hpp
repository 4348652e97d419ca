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
#include <string>
#include <vector>

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

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

// Runs `build` on the calling thread for one thread, else in an arena of build_concurrency(threads)
// slots: a build's tasks use the threads the user asked for, and no more.
template <class Build>
void run_build(unsigned threads, Build&& build) {
    if (threads == 1) {
        build();
        return;
    }
    tbb::task_arena arena(build_concurrency(threads));
    arena.execute(build);
}

// Checks an index against the `max` a node can encode; throws naming the structure otherwise.
inline std::uint32_t checked_node_index(std::size_t i, std::uint32_t max, const char* structure) {
    if (i > max)
        throw Error(std::string(structure) + ": more nodes or leaf references than its node format can address; "
                                             "the scene is too large (lower max_depth)");
    return static_cast<std::uint32_t>(i);
}

// Where the layout puts each piece, in depth-first order. An inner piece (its root's children built
// as pieces of their own): its root at `slot`, its children's pair at `base`. Any other piece: its
// root at `slot`, its other nodes from `base` on, its index entries from `first_index` on.
template <class Node>
struct PiecePlace {
    const Subtree<Node>* piece;
    std::uint32_t slot;
    std::size_t base, first_index;
};

// The places of `s`'s pieces, the nodes and index entries taken from `next_node` and `next_index` on:
// where one pass appending them depth-first, the children of every inner node adjacent, puts them.
// Throws naming the structure where an index passes what a node can encode.
template <class Node>
void place_pieces(const Subtree<Node>& s, std::uint32_t slot, std::size_t& next_node, std::size_t& next_index,
                  std::vector<PiecePlace<Node>>& places, std::uint32_t max_index, const char* structure) {
    if (s.left) {
        const auto pair = checked_node_index(next_node + 1, max_index, structure) - 1;
        places.push_back({&s, slot, pair, next_index});
        next_node += 2;
        place_pieces(*s.left, pair, next_node, next_index, places, max_index, structure);
        place_pieces(*s.right, pair + 1, next_node, next_index, places, max_index, structure);
        return;
    }
    places.push_back({&s, slot, next_node, next_index});
    next_index += s.indices.size();
    checked_node_index(next_index, max_index, structure);
    checked_node_index(next_node + s.nodes.size(), max_index, structure);
    next_node += s.nodes.size() - 1;
}

// Copies one piece to its place, its local numbering turned into the layout's.
template <class Node>
void copy_piece(const PiecePlace<Node>& at, std::vector<Node>& nodes, std::vector<std::uint32_t>& indices) {
    const Subtree<Node>& piece = *at.piece;
    if (piece.left) {
        nodes[at.slot] = piece.nodes[0].with_index(static_cast<std::uint32_t>(at.base));
        return;
    }
    std::copy(piece.indices.begin(), piece.indices.end(), indices.begin() + static_cast<std::ptrdiff_t>(at.first_index));
    auto place = [&](std::uint32_t local) {
        return local == 0 ? at.slot : static_cast<std::uint32_t>(at.base + local - 1);
    };
    for (std::uint32_t i = 0; i < piece.nodes.size(); ++i) {
        const Node& n = piece.nodes[i];
        nodes[place(i)] = n.is_leaf() ? n.with_index(static_cast<std::uint32_t>(at.first_index) + n.first())
                                      : n.with_index(place(n.children()));
    }
}

// Lays `s` out into `nodes` (whose element `slot` is its root's place) and `indices`. Every piece's
// place follows from the sizes of those before it in depth-first order, so the room is taken at once
// (growing it piece by piece copied and faulted in fresh pages each time: 0.8 ms on one thread, 2.1
// on two for Sibenik's BIH) and, with `parallel` (a parallel build, called within its arena), the
// pieces are copied on its threads: the same bytes, and no step on one thread after a build whose
// tree was not.
template <class Node>
void flatten(const Subtree<Node>& s, std::uint32_t slot, std::vector<Node>& nodes, std::vector<std::uint32_t>& indices,
             std::uint32_t max_index, const char* structure, bool parallel = false) {
    std::size_t next_node = nodes.size(), next_index = indices.size();
    std::vector<PiecePlace<Node>> places;
    place_pieces(s, slot, next_node, next_index, places, max_index, structure);
    nodes.resize(next_node);
    indices.resize(next_index);
    const auto copy = [&](std::size_t p) { copy_piece(places[p], nodes, indices); };
    if (parallel) tbb::parallel_for(std::size_t{0}, places.size(), copy);
    else
        for (std::size_t p = 0; p < places.size(); ++p) copy(p);
}

}  // namespace cellrt::detail
