#include "distributed/tile_window.hpp"

#include <fcntl.h>
#include <mpi.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <string>

#include "distributed/faults.hpp"

namespace cellrt::distributed {
namespace {

constexpr std::size_t kNameBytes = 64;

// The most memory the window takes: a frame's pixels, or this much where the frame's are fewer.
// Beyond it (huge tiles held far ahead by many ranks) the pixels travel as messages.
constexpr std::size_t kMostShared = std::size_t{1} << 30;


// Rank 0: makes the shared object `name` of `bytes` and maps it; null with `why` set when it cannot.
char* make_shared(const char* name, std::size_t bytes, std::string& why) {
    const int fd = shm_open(name, O_CREAT | O_EXCL | O_RDWR, 0600);
    if (fd < 0) {
        why = std::string("shm_open: ") + std::strerror(errno);
        return nullptr;
    }
    void* p = MAP_FAILED;
    // posix_fallocate reserves the pages now: a full /dev/shm fails here, not with SIGBUS at a store.
    if (ftruncate(fd, static_cast<off_t>(bytes)) != 0) why = std::string("ftruncate: ") + std::strerror(errno);
    else if (const int e = posix_fallocate(fd, 0, static_cast<off_t>(bytes)); e != 0)
        why = std::string("posix_fallocate: ") + std::strerror(e);
    else if ((p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0)) == MAP_FAILED)
        why = std::string("mmap: ") + std::strerror(errno);
    ::close(fd);
    if (p == MAP_FAILED) shm_unlink(name);
    return p == MAP_FAILED ? nullptr : static_cast<char*>(p);
}

// Another rank: maps rank 0's object, or null; null too where it is smaller than this rank expects
// (ranks started with other options), whose stores past its end would raise SIGBUS.
char* map_shared(const char* name, std::size_t bytes) {
    const int fd = shm_open(name, O_RDWR, 0600);
    if (fd < 0) return nullptr;
    struct stat st {};
    void* p = MAP_FAILED;
    if (fstat(fd, &st) == 0 && static_cast<std::size_t>(st.st_size) == bytes)
        p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    ::close(fd);
    return p == MAP_FAILED ? nullptr : static_cast<char*>(p);
}

}  // namespace

TileWindow::TileWindow(const Session& session, bool wanted, std::size_t bytes_each, std::size_t frame_bytes)
    : bytes_each_(bytes_each) {
    if (!wanted || session.size() < 2 || bytes_each == 0) return;
    // The ranks of each machine, in world order: the first of rank 0's machine is rank 0.
    MPI_Comm machine = MPI_COMM_NULL;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, session.rank(), MPI_INFO_NULL, &machine);
    // The test suite's faults (faults.hpp): apart:R seats rank R on a machine of its own, noshm:R denies
    // it the shared memory.
    if (fault_named("apart")) {
        MPI_Comm apart = MPI_COMM_NULL;
        MPI_Comm_split(machine, fault_named("apart", session.rank()) ? 1 : 0, session.rank(), &apart);
        MPI_Comm_free(&machine);
        machine = apart;
    }
    int first = session.rank(), sharing = 0, here = 0;
    MPI_Bcast(&first, 1, MPI_INT, 0, machine);
    MPI_Comm_size(machine, &sharing);
    MPI_Comm_rank(machine, &here);
    if (first != 0 || sharing < 2) {
        MPI_Comm_free(&machine);
        return;
    }
    const std::size_t bytes = bytes_each * static_cast<std::size_t>(sharing - 1);
    const bool fits = bytes <= std::max(frame_bytes, kMostShared);
    // Rank 0 makes the object and names it to the others ('\0' first: it did not, or could not).
    // Rank 0 alone decides, so that ranks started with other options cannot take other ways here.
    static unsigned frames = 0;
    char name[kNameBytes] = {};
    std::string why;
    char* base = nullptr;
    if (session.leader() && fits) {
        std::snprintf(name, sizeof name, "/cellrt-tiles-%ld-%u", static_cast<long>(getpid()), frames++);
        base = fault_named("noshm", 0) ? nullptr : make_shared(name, bytes, why);
        if (fault_named("noshm", 0)) why = "denied by CELLRT_MPI_FAULT";
        if (!base) name[0] = '\0';
    }
    MPI_Bcast(name, static_cast<int>(sizeof name), MPI_CHAR, 0, machine);
    if (name[0] != '\0' && !session.leader() && !fault_named("noshm", session.rank())) base = map_shared(name, bytes);
    int mapped = base != nullptr, all_mapped = 0;
    MPI_Allreduce(&mapped, &all_mapped, 1, MPI_INT, MPI_MIN, machine);
    if (session.leader() && name[0] != '\0') shm_unlink(name);  // every rank has it mapped, or has given up
    if (!all_mapped) {
        if (base) munmap(base, bytes);
        if (session.leader() && fits)
            std::fprintf(stderr, "%s: note: no shared memory for the tiles' pixels (%zu bytes%s%s); the ranks send them\n",
                         session.program().c_str(), bytes, why.empty() ? ", a rank could not map them" : ": ",
                         why.c_str());
    } else {
        base_ = base;
        bytes_ = bytes;
        writes_ = !session.leader();
        if (writes_) area_ = bytes_each * static_cast<std::size_t>(here - 1);
        if (session.leader()) {
            MPI_Group world = MPI_GROUP_NULL, machine_group = MPI_GROUP_NULL;
            MPI_Comm_group(MPI_COMM_WORLD, &world);
            MPI_Comm_group(machine, &machine_group);
            std::vector<int> local(static_cast<std::size_t>(sharing)), global(local.size());
            std::iota(local.begin(), local.end(), 0);
            MPI_Group_translate_ranks(machine_group, sharing, local.data(), world, global.data());
            MPI_Group_free(&machine_group);
            MPI_Group_free(&world);
            writers_.assign(static_cast<std::size_t>(session.size()), 0);
            for (std::size_t k = 1; k < global.size(); ++k) writers_[static_cast<std::size_t>(global[k])] = static_cast<int>(k);
        }
    }
    MPI_Comm_free(&machine);
}

int TileWindow::writers() const {
    return static_cast<int>(std::count_if(writers_.begin(), writers_.end(), [](int k) { return k > 0; }));
}

void TileWindow::sync() const { std::atomic_thread_fence(std::memory_order_seq_cst); }

void TileWindow::close() {
    if (!base_) return;
    munmap(base_, bytes_);
    base_ = nullptr;
    writes_ = false;
}

}  // namespace cellrt::distributed
