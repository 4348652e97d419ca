// cellrt-mpi under mpirun (docs/DISTRIBUTED.md): frames byte for byte those of the plain program for
// 1, 2 and 3 ranks, every shading and several structures, tile and packet sizes; a cache study split
// over ranks writes the plain program's results, and so do the benchmarks' sweeps (cellrt_bench-mpi,
// cellrt_scaling-mpi); a rank whose scene fails, a rank that dies, one that stops answering and a bad
// option each end every rank with a non-zero status, one message naming the rank and the cause, and no
// output file. Skipped where MPI was not found.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "cellrt/accel.hpp"

namespace cellrt {
namespace {

namespace fs = std::filesystem;

struct TempDir {
    fs::path path = fs::temp_directory_path() /
                    ("cellrt_mpi_" + std::to_string(::getpid()) + "_" +
                     std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    TempDir() { fs::create_directories(path); }
    ~TempDir() { fs::remove_all(path); }
};

std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

struct Outcome {
    int status;
    std::string err;
};

// Runs `command` through the shell with a time-out of its own (a hang fails the test instead of
// blocking it), its error output kept.
Outcome shell(const std::string& command, const fs::path& dir) {
    const fs::path err = dir / "stderr.txt";
    const std::string line = "timeout 120 " + command + " > /dev/null 2> '" + err.string() + "'";
    const int raw = std::system(line.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : 128, read(err)};
}

// mpirun as CI runs it: as root, more ranks than cores.
std::string mpirun(int ranks, const std::string& env = "") {
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    return std::string(CELLRT_MPIRUN) + " --allow-run-as-root --oversubscribe " + env + " -np " +
           std::to_string(ranks) + " ";
}

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// The shared-memory objects of cellrt-mpi's frames left in /dev/shm (none: each is unlinked once
// mapped).
std::size_t shared_objects_left() {
    std::size_t n = 0;
    std::error_code e;
    for (const auto& entry : fs::directory_iterator("/dev/shm", e))
        n += entry.path().filename().string().rfind("cellrt-tiles-", 0) == 0;
    return n;
}

int window_ranks(const fs::path& stats) { return nlohmann::json::parse(read(stats)).at("window_ranks").get<int>(); }

class Distributed : public ::testing::Test {
protected:
    void SetUp() override {
        if (!std::string(CELLRT_MPI_SKIP).empty()) GTEST_SKIP() << CELLRT_MPI_SKIP;
    }
    TempDir dir;
    const std::string mpi = CELLRT_MPI_CLI, plain = CELLRT_CLI;
};

constexpr const char* kScene = "'builtin:city?tris=3000&seed=3'";

TEST_F(Distributed, FramesAreTheOneProcessFrameForEveryRankCount) {
    struct Case {
        const char* options;
        int tile;
    };
    // Every shading, three structures, tiles cut at the frame's edges and packets cut at the tiles'.
    const Case cases[] = {{"--accel kd --shading direct --packet 8", 24},
                          {"--accel bih --shading ao --ao-samples 3 --packet 5", 16},
                          {"--accel bvh --shading diffuse --packet 16", 40}};
    for (const Case& c : cases) {
        const std::string name = std::to_string(&c - cases);
        const fs::path reference = dir.path / (name + "plain.pfm");
        const std::string frame = std::string(kScene) + " --size 97x61 " + c.options;
        ASSERT_EQ(shell(plain + " render " + frame + " -o " + reference.string(), dir.path).status, 0) << c.options;
        for (int ranks : {1, 2, 3}) {
            const fs::path out = dir.path / (name + "mpi" + std::to_string(ranks) + ".pfm");
            const fs::path stats = dir.path / (name + "mpi" + std::to_string(ranks) + ".json");
            // Three ranks also take the scene from rank 0's broadcast.
            // Two ranks hold one tile each, so a rank's one slot of the shared window is used again
            // for every tile after its first.
            const std::string command = mpirun(ranks) + mpi + " render " + frame + " --tile " + std::to_string(c.tile) +
                                        (ranks == 3 ? " --broadcast-scene" : "") + (ranks == 2 ? " --ahead 1" : "") +
                                        " -o " + out.string() + " --stats " + stats.string();
            const Outcome o = shell(command, dir.path);
            ASSERT_EQ(o.status, 0) << command << "\n" << o.err;
            EXPECT_EQ(read(out), read(reference)) << c.options << ", " << ranks << " ranks";
            // Each rank's tiles and time; the tiles add up to the frame's.
            const std::string report = read(stats);
            EXPECT_EQ(count(report, "\"tiles\""), static_cast<std::size_t>(ranks)) << report;
            EXPECT_NE(report.find("\"busy_seconds\""), std::string::npos);
            EXPECT_NE(report.find("\"frame_seconds\""), std::string::npos) << report;
            EXPECT_NE(report.find("\"float\""), std::string::npos) << report;
            // render's own time-out: cache-study's day, registered after it, was every command's
            // (found by audit, 2026-12-07).
            EXPECT_EQ(nlohmann::json::parse(report).at("rank_timeout_seconds").get<double>(), 120.0) << report;
            // Ranks on rank 0's machine (all here) write their pixels into its shared window.
            EXPECT_EQ(window_ranks(stats), ranks - 1) << report;
            // Every rank's threads listed in rank order, those of a rank that traced no tile too.
            const nlohmann::json j = nlohmann::json::parse(report);
            std::size_t threads = 0;
            for (const auto& r : j.at("ranks")) threads += r.at("threads").get<std::size_t>();
            EXPECT_EQ(j.at("workers").size(), threads) << report;
            EXPECT_EQ(j.at("threads").get<std::size_t>(), threads) << report;
        }
        // A PNG's pixels travel as its 8-bit bytes, made on each rank: the plain program's PNG.
        const fs::path png = dir.path / (name + "plain.png");
        ASSERT_EQ(shell(plain + " render " + frame + " -o " + png.string(), dir.path).status, 0) << c.options;
        for (int ranks : {2, 3}) {
            const fs::path out = dir.path / (name + "mpi" + std::to_string(ranks) + ".png");
            const fs::path stats = dir.path / (name + "mpi" + std::to_string(ranks) + "png.json");
            const std::string command = mpirun(ranks) + mpi + " render " + frame + " --tile " + std::to_string(c.tile) +
                                        " -o " + out.string() + " --stats " + stats.string();
            const Outcome o = shell(command, dir.path);
            ASSERT_EQ(o.status, 0) << command << "\n" << o.err;
            EXPECT_EQ(read(out), read(png)) << c.options << ", " << ranks << " ranks, PNG";
            EXPECT_NE(read(stats).find("\"srgb8\""), std::string::npos) << read(stats);
        }
        // The pixels as messages, floats and PNG bytes: the same frames.
        for (const char* ext : {".pfm", ".png"}) {
            const fs::path out = dir.path / (name + "messages" + ext);
            const fs::path stats = dir.path / (name + "messages" + ext + ".json");
            const std::string command = mpirun(3) + mpi + " render " + frame + " --tile " + std::to_string(c.tile) +
                                        " --gather messages -o " + out.string() + " --stats " + stats.string();
            const Outcome o = shell(command, dir.path);
            ASSERT_EQ(o.status, 0) << command << "\n" << o.err;
            EXPECT_EQ(read(out), read(dir.path / (name + "plain" + ext))) << c.options << ", messages" << ext;
            EXPECT_EQ(window_ranks(stats), 0) << read(stats);
        }
    }
    EXPECT_EQ(shared_objects_left(), 0u);
}

TEST_F(Distributed, CacheStudySplitOverRanksWritesTheOneProcessResults) {
    const std::string study = std::string(" cache-study ") + kScene +
                              " --size 64x48 --structures kd bih --traversals branched --access sync --threads 1 -o ";
    ASSERT_EQ(shell(plain + study + (dir.path / "plain").string(), dir.path).status, 0);
    // Every column but the last, the run's wall time.
    auto without_wall = [](const std::string& csv) {
        std::istringstream in(csv);
        std::string out, line;
        while (std::getline(in, line)) out += line.substr(0, line.rfind(',')) + "\n";
        return out;
    };
    const std::string csv = without_wall(read(dir.path / "plain" / "cache_study.csv"));
    ASSERT_GT(std::count(csv.begin(), csv.end(), '\n'), 100);
    for (int ranks : {2, 3}) {
        const fs::path out = dir.path / ("mpi" + std::to_string(ranks));
        const Outcome o = shell(mpirun(ranks) + mpi + study + out.string(), dir.path);
        ASSERT_EQ(o.status, 0) << o.err;
        EXPECT_EQ(without_wall(read(out / "cache_study.csv")), csv) << ranks << " ranks";
        EXPECT_EQ(read(out / "best_layouts.md"), read(dir.path / "plain" / "best_layouts.md")) << ranks << " ranks";
    }
}

// The ranks of a sweep wait at the end of their share for the longest share, whole runs long, so its
// time-out defaults to a day; a frame's ranks wait for one tile, 120 s. (A cache study whose shares
// ended more than 120 s apart was ended as if a rank had stopped answering.)
TEST_F(Distributed, ASweepWaitsForWholeRunsAFrameForOneTile) {
    auto default_timeout = [&](const std::string& command) {
        std::string help;
        FILE* p = ::popen((mpirun(1) + mpi + " " + command + " --help 2>&1").c_str(), "r");
        char buffer[4096];
        for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, p)) > 0;) help.append(buffer, n);
        EXPECT_EQ(::pclose(p), 0) << help;
        const auto at = help.find("--rank-timeout");
        // The option's entry: its line and its description's (CLI11 wraps it), up to the next option.
        return at == std::string::npos ? help : help.substr(at, help.find("\n  -", at) - at);
    };
    EXPECT_NE(default_timeout("cache-study").find("(default 86400)"), std::string::npos);
    EXPECT_NE(default_timeout("render").find("(default 120)"), std::string::npos);
}

// A failure of `program`: a non-zero status, one error line naming `rank` and holding `cause`, no
// output file, nor a temporary one beside it.
void expect_failure(const Outcome& o, const fs::path& out, const std::string& rank, const std::string& cause,
                    const std::string& program = "cellrt") {
    EXPECT_NE(o.status, 0) << o.err;
    EXPECT_EQ(count(o.err, program + ": error:"), 1u) << o.err;
    EXPECT_NE(o.err.find(program + ": error: " + rank), std::string::npos) << o.err;
    EXPECT_NE(o.err.find(cause), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(out));
    for (const auto& entry : fs::directory_iterator(out.parent_path()))
        EXPECT_EQ(entry.path().filename().string().find(out.stem().string()), std::string::npos) << entry.path();
}

// The benchmarks' sweeps: the same programs as the plain ones, split over the ranks a scene at a time.
class DistributedBench : public Distributed {
protected:
    void SetUp() override {
        Distributed::SetUp();
        if (!std::string(CELLRT_MPI_BENCH_SKIP).empty()) GTEST_SKIP() << CELLRT_MPI_BENCH_SKIP;
        write_scene(scenes, "tiny.obj");
        std::ofstream(scenes / "tiny" / "tiny.obj")
            << "v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
               "v -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n"
               "f 1 3 2\nf 1 4 3\nf 9 10 11\nf 9 11 12\nf 5 6 10\nf 5 10 9\nf 6 7 11\nf 6 11 10\n"
               "f 7 8 12\nf 7 12 11\nf 8 5 9\nf 8 9 12\n";
    }
    // A small scene from a file, laid out as the shared scenes are (FOLDER/NAME/NAME.json) and read
    // from `mesh` (SetUp writes tiny.obj: a ground quad and a box over it).
    static void write_scene(const fs::path& folder, const std::string& mesh) {
        fs::create_directories(folder / "tiny");
        std::ofstream(folder / "tiny" / "tiny.json")
            << R"({"name": "tiny", "mesh": ")" << mesh << R"(",
                  "camera": {"position": [5, 4, 6], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov_y_deg": 45},
                  "light": {"type": "point", "position": [-2, 8, 7], "color": [1, 1, 1]},
                  "image": {"width": 64, "height": 48}})";
    }
    fs::path scenes = dir.path / "scenes";
    // Three scenes, so that 2 and 3 ranks each get a share, one of them two scenes.
    std::string sweep() const {
        return " --scenes-dir " + scenes.string() +
               " --scenes 'builtin:city?tris=300&seed=3' tiny 'builtin:forest?tris=300' --size 32x24";
    }
};

// 1 where this build has Embree: the programs skip its configurations where it has not.
std::size_t embree_configs() {
    const std::vector<std::string> kinds = accelerator_kinds();
    return static_cast<std::size_t>(std::count(kinds.begin(), kinds.end(), "embree"));
}

// The JSON rows without the fields measured by a clock or from the process's memory.
nlohmann::json without_measurements(const std::string& text, const std::vector<std::string>& measured) {
    nlohmann::json rows = nlohmann::json::parse(text);
    for (nlohmann::json& row : rows)
        for (const std::string& key : measured) row.erase(key);
    return rows;
}

// The plain program's JSON, then the -mpi program's over 2 and 3 ranks, the same rows in the same
// order but for the measured fields.
void expect_same_sweep(const std::string& plain, const std::string& mpi, const std::string& options,
                       const std::vector<std::string>& measured, std::size_t rows, const fs::path& dir) {
    const fs::path reference = dir / "plain.json";
    const Outcome p = shell(plain + options + " --json " + reference.string(), dir);
    ASSERT_EQ(p.status, 0) << p.err;
    const nlohmann::json expected = without_measurements(read(reference), measured);
    EXPECT_EQ(expected.size(), rows) << expected.dump(1);
    for (int ranks : {2, 3}) {
        const fs::path out = dir / ("mpi" + std::to_string(ranks) + ".json");
        const Outcome o = shell(mpirun(ranks) + mpi + options + " --json " + out.string(), dir);
        ASSERT_EQ(o.status, 0) << o.err;
        EXPECT_EQ(without_measurements(read(out), measured), expected) << ranks << " ranks";
    }
}

TEST_F(DistributedBench, StructureSweepSplitOverRanksWritesTheOneProcessResults) {
    expect_same_sweep(CELLRT_BENCH, CELLRT_BENCH_MPI,
                      sweep() + " --configs embree:single kd:branched bih+auto --repeats 1 --builds 1",
                      {"build_seconds", "build_peak_mib", "primary_seconds", "shadow_seconds"},
                      3 * (2 + embree_configs()), dir.path);
}

TEST_F(DistributedBench, ScalingSweepSplitOverRanksWritesTheOneProcessResults) {
    expect_same_sweep(CELLRT_SCALING, CELLRT_SCALING_MPI,
                      sweep() + " --configs embree:single kd+auto --dispatch pull --packets 8 --workers 1 2 --repeats 1",
                      {"seconds", "busy_seconds", "started_seconds", "waiting_seconds", "tracing_share", "waking_share",
                       "waiting_share", "efficiency", "packet_time_ratio", "embree_seconds"},
                      3 * 2 * (1 + embree_configs()), dir.path);
}

TEST_F(DistributedBench, ARankWithoutTheScenesEndsEveryRank) {
    const fs::path out = dir.path / "results.json";
    const std::string options = " --scenes tiny --size 32x24 --repeats 1 --builds 1 --json " + out.string();
    // Ranks 1 and 2 are given a scenes folder that lacks the scene (mpirun's MPMD form).
    const Outcome o = shell(mpirun(1) + CELLRT_BENCH_MPI + " --scenes-dir " + scenes.string() + options + " : -np 2 " +
                                CELLRT_BENCH_MPI + " --scenes-dir " + (dir.path / "none").string() + options,
                            dir.path);
    expect_failure(o, out, "rank 1: ", "scene tiny: " + (dir.path / "none").string() + "/tiny/tiny.json not found, "
                   "which rank 0 has", "cellrt_bench");
    EXPECT_NE(o.err.find("(and 1 other rank)"), std::string::npos) << o.err;
}

TEST_F(DistributedBench, ARankWhoseRunFailsEndsEveryRank) {
    const fs::path out = dir.path / "results.json";
    // Rank 1's copy of the second scene names a mesh it does not have; rank 1 is given that scene.
    write_scene(dir.path / "broken", "gone.obj");
    const std::string options = " --scenes 'builtin:city?tris=300' tiny --configs kd --packets 8 --workers 1 "
                                "--repeats 1 --size 32x24 --json " + out.string();
    const Outcome o = shell(mpirun(1) + CELLRT_SCALING_MPI + " --scenes-dir " + scenes.string() + options +
                                " : -np 1 " + CELLRT_SCALING_MPI + " --scenes-dir " + (dir.path / "broken").string() +
                                options,
                            dir.path);
    expect_failure(o, out, "rank 1: ", "gone.obj", "cellrt_scaling");
}

TEST_F(DistributedBench, ABadOptionIsOneMessage) {
    const fs::path out = dir.path / "results.json";
    expect_failure(shell(mpirun(3) + CELLRT_SCALING_MPI + " --shading glossy --json " + out.string(), dir.path), out,
                   "rank 0: ", "--shading: ", "cellrt_scaling");
    expect_failure(shell(mpirun(2) + CELLRT_BENCH_MPI + " --size 12 --json " + out.string(), dir.path), out,
                   "rank 0: ", "--size '12' must be WIDTHxHEIGHT", "cellrt_bench");
    // A results file in a folder that is not there: refused before any run.
    const fs::path lost = dir.path / "missing" / "results.json";
    expect_failure(shell(mpirun(2) + CELLRT_SCALING_MPI + " --json " + lost.string(), dir.path), out, "rank 0: ",
                   lost.string() + ": no folder " + lost.parent_path().string() + " to write it in", "cellrt_scaling");
}

// --stats lists every rank's threads in rank order, those of ranks that traced no tile too (one tile
// among three ranks; found by audit, 2026-12-07: they were left out).
TEST_F(Distributed, StatsListEveryRanksWorkers) {
    const fs::path out = dir.path / "one.pfm", stats = dir.path / "one.json";
    const Outcome o = shell(mpirun(3) + mpi + " render " + kScene + " --size 16x16 --tile 16 --threads 1 -o " +
                                out.string() + " --stats " + stats.string(), dir.path);
    ASSERT_EQ(o.status, 0) << o.err;
    const nlohmann::json j = nlohmann::json::parse(read(stats));
    std::size_t tiles = 0;
    for (const auto& r : j.at("ranks")) tiles += r.at("tiles").get<std::size_t>();
    EXPECT_EQ(tiles, 1u);
    EXPECT_EQ(j.at("workers").size(), 3u) << j.dump();
    EXPECT_EQ(j.at("threads").get<std::size_t>(), 3u);
}

// A sweep's ranks run one command line: a rank started with another (mpirun's `A : B`) ran other
// runs, and the leader wrote uninitialised rows for the ones it expected (found by audit, 2026-12-07).
TEST_F(Distributed, ASweepsRanksWithAnotherCommandLineAreRefused) {
    const fs::path out = dir.path / "study";
    const std::string study = mpi + std::string(" cache-study ") + kScene + " --size 32x32 -o " + out.string();
    const Outcome o = shell(mpirun(2) + study + " : -np 1 " + study + " --structures kd", dir.path);
    expect_failure(o, out, "rank 2: ", "its command line ('cache-study' ");
    EXPECT_NE(o.err.find("): cache-study runs one command line on every rank"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(out));
}

// Ranks started with other commands would pair unlike collectives (found by review, 2026-12-07).
TEST_F(Distributed, RanksRunningOtherCommandsAreRefused) {
    const fs::path out = dir.path / "other.png";
    expect_failure(shell(mpirun(1) + mpi + " cache-study " + kScene + " --size 16x16 -o " + (dir.path / "s").string() +
                             " : -np 1 " + mpi + " render " + kScene + " --size 16x16 -o " + out.string(),
                         dir.path),
                   out, "rank 1: ", "it runs render, rank 0 cache-study");
}

TEST_F(DistributedBench, ASweepsRanksWithAnotherCommandLineAreRefused) {
    const fs::path results = dir.path / "results.json";
    const std::string bench = std::string(CELLRT_SCALING_MPI) + " --scenes 'builtin:city?tris=300' --size 8x8 "
                              "--repeats 1 --configs kd --json " + results.string();
    expect_failure(shell(mpirun(1) + bench + " : -np 1 " + bench + " --shading ao", dir.path), results, "rank 1: ",
                   "a sweep runs one command line on every rank", "cellrt_scaling");
}

TEST_F(Distributed, ARankWhoseSceneFailsEndsEveryRank) {
    const fs::path out = dir.path / "frame.png";
    // Rank 1 is given another scene (mpirun's MPMD form): it cannot load it.
    const Outcome o = shell(mpirun(1) + mpi + " render " + kScene + " -o " + out.string() + " : -np 2 " + mpi +
                                " render " + (dir.path / "missing.obj").string() + " -o " + out.string(),
                            dir.path);
    expect_failure(o, out, "rank 1: ", "missing.obj");
    EXPECT_NE(o.err.find("(and 1 other rank)"), std::string::npos) << o.err;
}

TEST_F(Distributed, RanksWithDifferentScenesAreRefused) {
    const fs::path out = dir.path / "frame.png";
    const Outcome o = shell(mpirun(1) + mpi + " render " + kScene + " -o " + out.string() + " : -np 1 " + mpi +
                                " render 'builtin:city?tris=3000&seed=4' -o " + out.string(),
                            dir.path);
    expect_failure(o, out, "rank 1: ", "differs from rank 0's");
}

// Found by review (2026-12-07): a rank started with another --size made a wrong frame, status 0 (the
// scene's fingerprint covers the view file's size only); a rank whose command line alone was bad, or
// that alone was given --broadcast-scene or --help, left the others waiting until their time-out, and
// the message named the time-out, not the cause.
TEST_F(Distributed, RanksStartedWithOtherOptionsAreRefusedAtOnce) {
    const fs::path out = dir.path / "frame.pfm";
    const std::string render = mpi + " render " + kScene + " --rank-timeout 60 -o " + out.string();
    expect_failure(shell(mpirun(2) + render + " --size 64x64 : -np 1 " + render + " --size 64x65", dir.path), out,
                   "rank 2: ", "its frame (64x65, direct shading, tiles of 128 ahead 3, float pixels by window) differs "
                   "from rank 0's (64x64, ");
    expect_failure(shell(mpirun(1) + render + " : -np 1 " + render + " --shading ao", dir.path), out, "rank 1: ",
                   "its frame (");
    const auto started = std::chrono::steady_clock::now();
    expect_failure(shell(mpirun(2) + render + " : -np 1 " + render + " --bogus", dir.path), out, "rank 2: ",
                   "The following argument was not expected: --bogus (see --help)");
    expect_failure(shell(mpirun(1) + render + " --broadcast-scene : -np 1 " + render, dir.path), out, "rank 1: ",
                   "it was started without --broadcast-scene, rank 0 with it");
    // --help on one rank only: its exit used to be paired with the others' first agreement.
    expect_failure(shell(mpirun(1) + render + " : -np 1 " + render + " --help", dir.path), out, "rank 1: ",
                   "it asked for --help or --version, rank 0 did not ask");
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(50)) << "a rank waited out its time-out";
}

TEST_F(Distributed, ABadOptionIsOneMessage) {
    const fs::path out = dir.path / "frame.png";
    expect_failure(shell(mpirun(3) + mpi + " render " + kScene + " --packet 0 -o " + out.string(), dir.path), out,
                   "rank 0: ", "--packet 0 must lie in [1, 256]");
    expect_failure(shell(mpirun(2) + mpi + " info " + kScene, dir.path), out, "rank 0: ", "info runs in one process");
    // At one rank too (its tiles gave other cache figures without a word; found by audit, 2026-12-07).
    expect_failure(shell(mpirun(1) + mpi + " render " + kScene + " --local-store -o " + out.string(), dir.path), out,
                   "rank 0: ", "--local-store models one process's workers over the whole frame: run it with cellrt, "
                   "not cellrt-mpi");
    // Said once, not by every rank (2026-12-07).
    const fs::path study = dir.path / "study";
    expect_failure(shell(mpirun(2) + mpi + " cache-study 'builtin:spheres?tris=200' 'builtin:spheres?tris=300' --size "
                         "32x32 --sample 4 --packet 4 --traversals branched --access sync --structures kd --sweeps node "
                         "--out " + study.string(), dir.path),
                   study, "rank 0: ", "builtin:spheres?tris=300 and builtin:spheres?tris=200 are both the scene 'spheres'");
    // The command line's own check, on every rank: not a time-out of NaN seconds.
    const Outcome nan = shell(mpirun(2) + mpi + " render " + kScene + " --rank-timeout nan -o " + out.string(), dir.path);
    EXPECT_NE(nan.status, 0);
    EXPECT_NE(nan.err.find("--rank-timeout: 'nan' is not a finite decimal number"), std::string::npos) << nan.err;
    EXPECT_FALSE(fs::exists(out));
}

TEST_F(Distributed, RanksWithoutSharedMemorySendTheirPixels) {
    const std::string frame = std::string(kScene) + " --size 97x61";
    for (const char* ext : {".pfm", ".png"})
        ASSERT_EQ(shell(plain + " render " + frame + " -o " + (dir.path / (std::string("plain") + ext)).string(),
                        dir.path).status, 0);
    struct Case {
        const char* fault;
        const char* ext;
        int window_ranks;  // of 3
        bool note;
    };
    // Rank 0 cannot make the memory, or rank 2 cannot map it: every rank sends its pixels, and rank 0
    // says so in one line. Rank 2 on a machine of its own: it sends them, rank 1 writes them.
    const Case cases[] = {{"noshm:0", ".pfm", 0, true}, {"noshm:2", ".png", 0, true}, {"apart:2", ".pfm", 1, false}};
    for (const Case& c : cases) {
        const fs::path out = dir.path / (std::string(c.fault + 6) + c.ext);
        const fs::path stats = dir.path / (std::string(c.fault + 6) + c.ext + ".json");
        const Outcome o = shell(mpirun(3, std::string("-x CELLRT_MPI_FAULT=") + c.fault) + mpi + " render " + frame +
                                    " --tile 16 -o " + out.string() + " --stats " + stats.string(),
                                dir.path);
        ASSERT_EQ(o.status, 0) << c.fault << "\n" << o.err;
        EXPECT_EQ(read(out), read(dir.path / (std::string("plain") + c.ext))) << c.fault;
        EXPECT_EQ(window_ranks(stats), c.window_ranks) << c.fault;
        EXPECT_EQ(count(o.err, "cellrt: note: no shared memory for the tiles' pixels"), c.note ? 1u : 0u) << o.err;
    }
    EXPECT_EQ(shared_objects_left(), 0u);
}

TEST_F(Distributed, ARankThatDiesEndsTheJob) {
    const fs::path out = dir.path / "frame.png";
    const Outcome o = shell(mpirun(2, "-x CELLRT_MPI_FAULT=kill:1") + mpi + " render " + kScene +
                                " --size 200x200 --tile 8 -o " + out.string(), dir.path);
    EXPECT_NE(o.status, 0) << o.err;
    // mpirun itself says which rank died, and how.
    EXPECT_NE(o.err.find("rank 1"), std::string::npos) << o.err;
    EXPECT_NE(o.err.find("signal 9"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(out));
}

TEST_F(Distributed, ARankThatStopsAnsweringTimesOut) {
    const fs::path out = dir.path / "frame.png";
    const auto start = std::chrono::steady_clock::now();
    const Outcome o = shell(mpirun(3, "-x CELLRT_MPI_FAULT=stall:2") + mpi + " render " + kScene +
                                " --size 200x200 --tile 8 --rank-timeout 2 -o " + out.string(), dir.path);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(o.status, 0) << o.err;
    EXPECT_EQ(count(o.err, "cellrt: error:"), 1u) << o.err;
    EXPECT_NE(o.err.find("cellrt: error: rank 0: rank 2 has returned no tile for 2 s"), std::string::npos) << o.err;
    EXPECT_LT(seconds, 30.0);
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace cellrt
