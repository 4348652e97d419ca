// The cellrt program end to end: a render interrupted with Ctrl-C stops promptly, exits with 130 and
// leaves no file (partial or temporary) under the output name; images are the same for every
// structure, SIMD setting, dispatch mode, worker count and packet size; bad options are refused.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "cellrt/image.hpp"

extern char** environ;

namespace cellrt {
namespace {

namespace fs = std::filesystem;

struct TempDir {
    fs::path path = fs::temp_directory_path() / ("cellrt_cli_" + std::to_string(::getpid()) + "_" +
                                                 std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    TempDir() { fs::create_directories(path); }
    ~TempDir() { fs::remove_all(path); }
};

// Runs the program with its output thrown away, or its error output written to `error_file`.
pid_t spawn(const std::vector<std::string>& args, const std::string& error_file = "/dev/null") {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = 0;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, error_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int rc = posix_spawn(&pid, CELLRT_CLI, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    return rc == 0 ? pid : -1;
}

int wait_exit(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int run(const std::vector<std::string>& args) {
    std::vector<std::string> all{CELLRT_CLI};
    all.insert(all.end(), args.begin(), args.end());
    return wait_exit(spawn(all));
}

TEST(Cli, InterruptedRenderLeavesNoFile) {
    for (const char* dispatch : {"pull", "mailbox"}) {
        TempDir dir;
        const fs::path out = dir.path / "frame.png";
        // Large enough to run for many seconds, so the interrupt lands mid-render.
        const pid_t pid = spawn({CELLRT_CLI, "render", "builtin:spheres?tris=20000", "--accel", "brute", "--simd", "off",
                                 "--size", "1024x1024", "--threads", "2", "--packet", "4", "--dispatch", dispatch, "-o",
                                 out.string()});
        ASSERT_GT(pid, 0);
        std::this_thread::sleep_for(std::chrono::milliseconds(700));
        const auto sent = std::chrono::steady_clock::now();
        kill(pid, SIGINT);
        EXPECT_EQ(wait_exit(pid), 130) << dispatch;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
        EXPECT_LT(seconds, 2.0) << dispatch << ": the render must stop within a packet or two";
        EXPECT_TRUE(fs::is_empty(dir.path)) << dispatch << ": nothing may be left under the output's folder";
    }
}

// Every path through the program gives the same bits, under every shading: structures, SIMD,
// traversals, dispatch modes, worker counts and packet sizes (including packets that do not divide the
// image).
TEST(Cli, SameImageForEveryPath) {
    TempDir dir;
    const std::string scene = "builtin:spheres?tris=3000";
    for (const std::vector<std::string>& shading : std::vector<std::vector<std::string>>{
             {"--shading", "direct"}, {"--shading", "ao", "--ao-samples", "3"}, {"--shading", "diffuse"}}) {
        auto render = [&](const std::string& name, std::vector<std::string> extra) {
            const fs::path out = dir.path / (name + "_" + shading[1] + ".pfm");
            std::vector<std::string> args{"render", scene, "--size", "67x45", "-o", out.string()};
            args.insert(args.end(), shading.begin(), shading.end());
            args.insert(args.end(), extra.begin(), extra.end());
            EXPECT_EQ(run(args), 0) << name << " " << shading[1];
            return read_pfm(out.string());
        };
        const Image reference = render("brute", {"--accel", "brute", "--simd", "off", "--threads", "1"});
        const std::vector<std::pair<std::string, std::vector<std::string>>> paths = {
            {"kd_auto", {"--accel", "kd"}},
            {"kd_rec", {"--accel", "kd", "--traversal", "rec", "--threads", "3", "--packet", "5"}},
            {"kd_branchless_mailbox", {"--accel", "kd", "--traversal", "branchless", "--dispatch", "mailbox", "--packet", "2"}},
            {"bih_auto_mailbox", {"--accel", "bih", "--dispatch", "mailbox", "--threads", "2", "--packet", "16"}},
            {"bih_branched", {"--accel", "bih", "--traversal", "branched", "--packet", "1"}},
            {"kd_portable", {"--accel", "kd", "--simd", "portable", "--packet", "7"}},
            {"brute_auto", {"--accel", "brute", "--packet", "8"}},
            {"bvh", {"--accel", "bvh", "--packet", "4"}},
            {"routed", {"--accel", "auto", "--threads", "2"}},
        };
        for (const auto& [name, extra] : paths) {
            const Image img = render(name, extra);
            ASSERT_EQ(img.pixels.size(), reference.pixels.size()) << name;
            EXPECT_EQ(std::memcmp(img.pixels.data(), reference.pixels.data(), img.pixels.size() * sizeof(Vec3)), 0)
                << name << " " << shading[1];
        }
    }
}

// The shadings differ from one another, and AO with more samples is another image: the options reach
// the renderer.
TEST(Cli, ShadingsGiveTheirOwnImages) {
    TempDir dir;
    auto render = [&](const std::string& name, std::vector<std::string> extra) {
        const fs::path out = dir.path / (name + ".pfm");
        std::vector<std::string> args{"render", "builtin:spheres?tris=3000", "--size", "40x30", "-o", out.string()};
        args.insert(args.end(), extra.begin(), extra.end());
        EXPECT_EQ(run(args), 0) << name;
        return read_pfm(out.string());
    };
    const std::vector<Image> images = {render("direct", {}), render("ao", {"--shading", "ao"}),
                                       render("ao8", {"--shading", "ao", "--ao-samples", "8"}),
                                       render("diffuse", {"--shading", "diffuse"})};
    for (std::size_t a = 0; a < images.size(); ++a)
        for (std::size_t b = a + 1; b < images.size(); ++b)
            EXPECT_NE(std::memcmp(images[a].pixels.data(), images[b].pixels.data(),
                                  images[a].pixels.size() * sizeof(Vec3)),
                      0)
                << a << " " << b;
}

TEST(Cli, RefusesBadOptions) {
    TempDir dir;
    const std::string out = (dir.path / "x.png").string();
    for (const auto& args : std::vector<std::vector<std::string>>{
             {"render", "--packet", "0", "-o", out},
             {"render", "--dispatch", "push", "-o", out},
             {"render", "--simd", "avx9", "-o", out},
             {"render", "--accel", "octree", "-o", out},
             {"render", "--accel", "kd", "-P", "bins=1", "-o", out},
             {"render", "--accel", "bih", "--traversal", "rec", "-o", out},
             {"render", "--size", "0x5", "-o", out},
             {"render", "--shading", "phong", "-o", out},
             {"render", "--shading", "ao", "--ao-samples", "0", "-o", out},
             {"render", "--ao-samples", "4", "-o", out},
             {"render", "-o", (dir.path / "no" / "such" / "x.png").string()},
         }) {
        EXPECT_NE(run(args), 0) << args[1] << " " << args[2];
        EXPECT_FALSE(fs::exists(out));
    }
}

// The library's messages speak of what a value means; the program puts the option in front.
TEST(Cli, NamesTheOptionAtFault) {
    TempDir dir;
    const std::string out = (dir.path / "x.png").string(), existing = (dir.path / "existing.png").string();
    std::ofstream(existing) << "mine";
    const std::string errors = (dir.path / "errors.txt").string();
    for (const auto& [args, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
             {{"render", "--packet", "0", "-o", out}, "--packet 0 must lie in [1, 256]"},
             {{"render", "--dispatch", "push", "-o", out}, "--dispatch: dispatch mode 'push' is not one of: pull, mailbox"},
             {{"render", "--simd", "avx9", "-o", out},
              "--simd: SIMD instruction set 'avx9' is not one of: auto, off, portable, sse, avx2, avx512"},
             {{"render", "-o", existing}, existing + ": file exists (pass --overwrite to replace it)"},
             {{"render", "--shading", "phong", "-o", out}, "--shading: shading 'phong' is not one of: direct, ao, diffuse"},
             {{"render", "--shading", "ao", "--ao-samples", "65", "-o", out}, "--ao-samples 65 must lie in [1, 64]"},
             {{"render", "--ao-samples", "4", "-o", out}, "--ao-samples needs --shading ao"},
             {{"info", "builtin:spheres?tris=100", "--accel", "kd", "--simd", "avx9"},
              "--simd: SIMD instruction set 'avx9' is not one of: auto, off, portable, sse, avx2, avx512"},
         }) {
        std::vector<std::string> all{CELLRT_CLI};
        all.insert(all.end(), args.begin(), args.end());
        EXPECT_NE(wait_exit(spawn(all, errors)), 0) << args[1];
        std::ifstream in(errors);
        const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        EXPECT_EQ(text, "cellrt: error: " + message + "\n");
        EXPECT_FALSE(fs::exists(out));
    }
}

}  // namespace
}  // namespace cellrt
