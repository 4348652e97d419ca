// Tiles' pixels through memory that rank 0 shares with the ranks on its machine. Between processes
// of one machine a tile's pixels sent as a message move in fragments, and only while both sides call
// MPI: with 16 ranks on one machine the ranks waited for their pixels to reach rank 0 for half the
// frame (docs/DISTRIBUTED.md). Instead, a rank on rank 0's machine writes a traced tile's pixels
// straight into memory rank 0 maps too, and sends rank 0 only the tile's header; ranks on other
// machines (MPI_COMM_TYPE_SHARED tells them apart) send their pixels as before. Each writer has an
// area of its own (tile_farm.cpp cuts it into one slot per tile the rank may hold, reused in turn: a
// few tiles' bytes, not the frame's, so that its pages are touched once, not once per tile).
//
// The memory is a POSIX shared-memory object, not an MPI shared window: Open MPI's
// MPI_Win_allocate_shared hangs or ends the job when the machine's shared memory cannot hold the
// segment, where this one is made and checked (posix_fallocate) by rank 0 alone, and the ranks agree
// to go without it. Its name is unlinked as soon as every rank has mapped it, so nothing is left
// behind in /dev/shm, whatever happens later (a rank 0 killed in the moment between making and
// unlinking it would leave it).
//
// Ordering: a writer stores, calls sync() and then sends the header; rank 0 receives the header,
// calls sync(), reads, calls sync() again and only then tells the writer that the slot is free (the
// message passes between the sync()s). Only the thread that made the session calls MPI; a tracer
// thread's stores reach it through a mutex first.
#pragma once

#include <cstddef>
#include <vector>

#include "distributed/session.hpp"

namespace cellrt::distributed {

class TileWindow {
public:
    // Collective over MPI_COMM_WORLD, every rank with the same arguments: with `wanted` and more than
    // one rank, each other rank on rank 0's machine gets `bytes_each` of memory shared with rank 0,
    // unless they come to more than the frame's `frame_bytes` and 1 GiB. When the machine cannot give
    // them, rank 0 says so in one line and every rank goes without: its pixels travel as messages.
    // The calls are MPI's blocking collectives (no time-out): every rank makes them before its tiles.
    TileWindow(const Session& session, bool wanted, std::size_t bytes_each, std::size_t frame_bytes);
    ~TileWindow() { close(); }
    TileWindow(const TileWindow&) = delete;
    TileWindow& operator=(const TileWindow&) = delete;

    // Whether this rank writes its tiles' pixels into the window (rank 0 writes into the frame itself).
    bool writes() const { return writes_; }
    // Rank 0: whether rank `r` does.
    bool written_by(int r) const { return r > 0 && static_cast<std::size_t>(r) < writers_.size() && writers_[r] > 0; }
    // Rank 0: how many ranks do.
    int writers() const;
    // A writer's own area.
    char* mine() const { return base_ + area_; }
    // Rank 0: the area of writer `r`.
    char* of(int r) const { return base_ + bytes_each_ * static_cast<std::size_t>(writers_[static_cast<std::size_t>(r)] - 1); }
    // Orders this rank's stores to the window before, and the others' after, what follows.
    void sync() const;
    // Unmaps the window (each rank on its own: nothing waits for another rank).
    void close();

private:
    char* base_ = nullptr;
    std::size_t bytes_ = 0, bytes_each_ = 0, area_ = 0;
    bool writes_ = false;
    std::vector<int> writers_;  // rank 0: by world rank, its rank among those sharing the window (0: none)
};

}  // namespace cellrt::distributed
