#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fcntl.h>
#include <fstream>
#include <future>
#include <csignal>
#include <sys/stat.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "core/files.hpp"
#include "error_of.hpp"
#include "sanitizers.hpp"

namespace cellrt {
namespace {

Image render_with(const Scene& scene, const std::string& accel_kind, unsigned threads, int w, int h) {
    const auto accel = make_accelerator(scene.triangles, AccelConfig{accel_kind});
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.threads = threads;
    o.packet = 8;
    return render(scene, *accel, o);
}

bool same_bits(const Image& a, const Image& b) {
    return a.width == b.width && a.height == b.height &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(Vec3)) == 0;
}

TEST(Render, SameImageAtOneAndFourThreads) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=800");
    const Image one = render_with(scene, "brute", 1, 61, 47);
    const Image four = render_with(scene, "brute", 4, 61, 47);
    EXPECT_TRUE(same_bits(one, four));
}

// The form that reuses a frame's pixels: a moved-from Image keeps its sides and holds no pixels, and
// was written past its end (found by audit, 2026-12-07); one of other sides is remade.
TEST(Render, AFrameWithoutItsPixelsIsRemade) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=800");
    const Image expected = render_with(scene, "brute", 2, 61, 47);
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"brute"});
    RenderOptions o;
    o.width = 61;
    o.height = 47;
    o.threads = 2;
    o.packet = 8;
    Image frame = render(scene, *accel, o);
    const Image kept = std::move(frame);
    render(scene, *accel, o, frame);  // NOLINT(bugprone-use-after-move): the moved-from state is the case
    EXPECT_TRUE(same_bits(frame, expected));
    EXPECT_TRUE(same_bits(kept, expected));
    Image other(3, 5);
    render(scene, *accel, o, other);
    EXPECT_TRUE(same_bits(other, expected));
}

// A unit square floor lit from straight above, with a small box floating over its centre: the point
// under the box is in shadow, a point near a corner is lit, and a ray above the horizon sees sky.
TEST(Render, ShadowedAndLitPixelsWhereTheyMustBe) {
    Scene scene;
    scene.triangles = {{{-2.f, 0.f, -2.f}, {-2.f, 0.f, 2.f}, {2.f, 0.f, 2.f}},
                       {{-2.f, 0.f, -2.f}, {2.f, 0.f, 2.f}, {2.f, 0.f, -2.f}},
                       // occluder: a horizontal square at y = 1 over the centre
                       {{-0.3f, 1.f, -0.3f}, {-0.3f, 1.f, 0.3f}, {0.3f, 1.f, 0.3f}},
                       {{-0.3f, 1.f, -0.3f}, {0.3f, 1.f, 0.3f}, {0.3f, 1.f, -0.3f}}};
    scene.light.position = {0.f, 5.f, 0.f};
    // Seen obliquely, so that the floor under the occluder is visible past it.
    scene.camera = {{0.f, 3.f, 5.f}, {0.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, 60.f};
    const int w = 96, h = 96;
    const Image img = render_with(scene, "brute", 2, w, h);
    const PinholeCamera cam(scene.camera, w, h);
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"brute"});
    // Find pixels whose primary ray hits the floor near (0,0,0) (under the occluder) and near (1.5,0,1.5).
    float best_centre = kInfinity, best_corner = kInfinity;
    Vec3 centre_px, corner_px;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Ray r = cam.primary(x, y);
            Hit hit;
            accel->intersect(std::span(&r, 1), std::span(&hit, 1));
            if (!hit.is_hit() || hit.prim > 1) continue;
            const Vec3 p = r.org + r.dir * hit.t;
            const float dc = length(p), dk = length(p - Vec3{1.5f, 0.f, 1.5f});
            if (dc < best_centre) best_centre = dc, centre_px = img.at(x, y);
            if (dk < best_corner) best_corner = dk, corner_px = img.at(x, y);
        }
    ASSERT_LT(best_centre, 0.2f);
    ASSERT_LT(best_corner, 0.2f);
    EXPECT_GT(corner_px.x, 0.5f) << "floor away from the occluder must be lit";
    EXPECT_LT(centre_px.x, 0.15f) << "floor under the occluder must be in shadow (ambient only)";
    const Vec3 sky_px = img.at(0, 0);
    EXPECT_GT(sky_px.z, sky_px.x) << "top row sees the blue sky";
}

TEST(Render, WritesPfmExactlyAndRefusesToOverwrite) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=400");
    const Image img = render_with(scene, "brute", 2, 20, 10);
    const auto dir = std::filesystem::temp_directory_path() / ("cellrt_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "img.pfm").string();
    write_image(img, path, false);
    EXPECT_TRUE(same_bits(read_pfm(path), img));
    try {
        write_image(img, path, false);
        ADD_FAILURE() << "an existing file was replaced";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), path + ": file exists and overwrite is off");
    }
    EXPECT_NO_THROW(write_image(img, path, true));
    EXPECT_THROW(write_image(img, (dir / "no" / "such" / "x.png").string(), false), Error);
    EXPECT_THROW(write_image(img, (dir / "x.bmp").string(), false), Error);
    std::filesystem::remove_all(dir);
}

// What an image is written to when it is not a plain new file: a pipe (as /dev/null or /dev/stdout,
// which renaming over would have replaced by a file: found by review, 2026-12-06) is written in place
// and stays a pipe; a link to a file keeps its link and the file is replaced; a folder is refused; a
// name of 250 bytes, whose temporary name would pass the file system's 255, is written; a path under
// /proc (or /dev) that leads to a log file is appended to.
TEST(Render, ImagesGoIntoPipesAndThroughLinks) {
    const Image img = render_with(make_builtin_scene("builtin:spheres?tris=400"), "brute", 2, 4, 2);
    const auto dir = std::filesystem::temp_directory_path() / ("cellrt_out_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string fifo = (dir / "pipe.pfm").string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    // The reader's end, open before the write (without waiting for a writer), so that the writer's
    // open does not wait either; the image (120 bytes) fits the pipe's buffer.
    const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
    ASSERT_GE(reader, 0);
    write_image(img, fifo, false);
    std::string piped(4096, '\0');
    const ssize_t got = ::read(reader, piped.data(), piped.size());
    ::close(reader);
    piped.resize(got > 0 ? static_cast<std::size_t>(got) : 0);
    struct stat st {};
    ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
    EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the pipe was replaced";
    const std::string file = (dir / "file.pfm").string(), link = (dir / "link.pfm").string();
    write_image(img, file, false);
    std::ifstream written(file, std::ios::binary);
    EXPECT_EQ(piped, (std::string{std::istreambuf_iterator<char>(written), std::istreambuf_iterator<char>()}));
    std::filesystem::create_symlink("file.pfm", link);
    EXPECT_EQ(test::error_of([&] { write_image(img, link, false); }), link + ": file exists and overwrite is off");
    write_image(img, link, true);
    EXPECT_TRUE(std::filesystem::is_symlink(link));
    EXPECT_TRUE(same_bits(read_pfm(file), img));
    // A link whose file is not there yet is written through, as a shell's `>` does (the rename used
    // to replace the link by the file; 2026-12-07).
    const std::string ahead = (dir / "ahead.pfm").string();
    std::filesystem::create_symlink("later.pfm", ahead);
    write_image(img, ahead, false);
    EXPECT_TRUE(std::filesystem::is_symlink(ahead));
    EXPECT_TRUE(same_bits(read_pfm((dir / "later.pfm").string()), img));
    // A loop of links is refused as a shell refuses it, not broken by a file put in its way.
    std::filesystem::create_symlink("loop_b.pfm", dir / "loop_a.pfm");
    std::filesystem::create_symlink("loop_a.pfm", dir / "loop_b.pfm");
    const std::string loop = (dir / "loop_a.pfm").string();
    EXPECT_EQ(test::error_of([&] { write_image(img, loop, true); }), loop + ": too many levels of links");
    EXPECT_TRUE(std::filesystem::is_symlink(dir / "loop_b.pfm"));
    const std::string folder = (dir / "folder.pfm").string();
    std::filesystem::create_directories(folder);
    EXPECT_EQ(test::error_of([&] { write_image(img, folder, true); }), folder + ": is a folder, not a file");
    const std::string long_name = (dir / (std::string(246, 'a') + ".pfm")).string();
    write_image(img, long_name, false);
    EXPECT_TRUE(same_bits(read_pfm(long_name), img));
    // A path under /proc (or /dev, as /dev/stdout) that leads to a file, as a shell's `>> log` makes
    // it: appended to, not renamed over nor truncated.
    const std::string log = (dir / "log.txt").string();
    std::ofstream(log) << "first\n";
    const int fd = ::open(log.c_str(), O_WRONLY | O_APPEND);
    ASSERT_GE(fd, 0);
    write_file_atomically("/proc/self/fd/" + std::to_string(fd), "second\n", false);
    ::close(fd);
    std::ifstream logged(log);
    EXPECT_EQ((std::string{std::istreambuf_iterator<char>(logged), std::istreambuf_iterator<char>()}), "first\nsecond\n");
    logged.close();
    // One that leads to a file no descriptor of the process writes (`/dev/stdin < kept.json`, a path
    // through /proc/self/root or /proc/self/cwd) is that file: refused without overwrite, replaced
    // with it, and an input's other name (found by audit, 2026-12-07: appended to in every case).
    const int read_only = ::open(log.c_str(), O_RDONLY);
    ASSERT_GE(read_only, 0);
    const std::string through_fd = "/proc/self/fd/" + std::to_string(read_only);
    EXPECT_EQ(test::error_of([&] { write_file_atomically(through_fd, "third\n", false); }),
              through_fd + ": file exists and overwrite is off");
    ::close(read_only);
    const std::string through_root = "/proc/self/root" + std::filesystem::absolute(log).string();
    EXPECT_EQ(test::error_of([&] { check_output_file(through_root, false); }),
              through_root + ": file exists (pass --overwrite to replace it)");
    EXPECT_EQ(test::error_of([&] { check_distinct_files({{"--stats", through_root}}, {{"scene", log}}); }),
              "--stats " + through_root + " names the scene " + log + ", which it would replace");
    write_file_atomically(through_root, "replaced\n", true);
    std::ifstream replaced(log);
    EXPECT_EQ((std::string{std::istreambuf_iterator<char>(replaced), std::istreambuf_iterator<char>()}), "replaced\n");
    EXPECT_FALSE(std::filesystem::is_symlink(log));
    std::filesystem::remove_all(dir);
}

// A pipe whose reader comes later is waited for; a signal during the wait ends it with an error, even
// under a handler that asks for restarts (a blocked open was restarted after every signal: a Ctrl-C
// could not end `cellrt render -o pipe` with no reader; found by audit, 2026-12-07).
TEST(Render, APipeIsWaitedForUntilItsReaderComesOrASignal) {
    const auto dir = std::filesystem::temp_directory_path() / ("cellrt_pipe_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string fifo = (dir / "pipe.txt").string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const std::string bytes(200000, 'x');  // more than a pipe holds: the writer waits for the reader too
    std::fflush(stdout);
    const pid_t reader = ::fork();
    ASSERT_GE(reader, 0);
    if (reader == 0) {
        ::usleep(300000);
        std::ifstream in(fifo, std::ios::binary);
        const std::string got{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        ::_exit(got == bytes ? 0 : 5);
    }
    std::string failure;  // the reader is ended first, so that it does not wait for a writer for ever
    try {
        write_file_atomically(fifo, bytes, false);
    } catch (const std::exception& e) {
        failure = e.what();
        ::kill(reader, SIGKILL);
    }
    EXPECT_EQ(failure, "");
    int status = 0;
    ASSERT_EQ(::waitpid(reader, &status, 0), reader);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
    const pid_t writer = ::fork();
    ASSERT_GE(writer, 0);
    if (writer == 0) {
        struct sigaction on_alarm {};
        on_alarm.sa_handler = [](int) {};
        on_alarm.sa_flags = SA_RESTART;
        ::sigaction(SIGALRM, &on_alarm, nullptr);
        ::alarm(1);
        const std::string message = test::error_of([&] { write_file_atomically(fifo, "no one reads\n", false); });
        ::_exit(message == fifo + ": interrupted while waiting for a reader of the pipe" ? 0 : 6);
    }
    ASSERT_EQ(::waitpid(writer, &status, 0), writer);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
    // A cancel flag already set (a signal before the wait began) ends it at once.
    std::atomic<bool> cancel{true};
    set_write_cancel(&cancel);
    EXPECT_EQ(test::error_of([&] { write_file_atomically(fifo, "late\n", false); }),
              fifo + ": interrupted while waiting for a reader of the pipe");
    set_write_cancel(nullptr);
    // A socket also answers ENXIO: refused, not waited for as a pipe (found by review, 2026-12-07).
    const std::string socket_path = (dir / "s").string();
    const int listener = ::socket(AF_UNIX, SOCK_STREAM, 0);
    ASSERT_GE(listener, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, socket_path.c_str(), sizeof address.sun_path - 1);
    ASSERT_EQ(::bind(listener, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
    EXPECT_EQ(test::error_of([&] { write_file_atomically(socket_path, "x\n", false); }),
              socket_path + ": cannot be opened for writing (No such device or address)");
    ::close(listener);
    std::filesystem::remove_all(dir);
}

// Found by review (2026-12-07): `cellrt_scaling --json /dev/stdout > log` lost the results: a second
// descriptor of the redirected file wrote them at offset 0, and the tables the program had buffered
// were then flushed over them. Bytes for the process's own standard output go through its stream.
TEST(Render, TheProcesssOwnStandardOutputIsWrittenThroughItsStream) {
    const std::string log =
        (std::filesystem::temp_directory_path() / ("cellrt_stdout_" + std::to_string(::getpid()) + ".txt")).string();
    std::fflush(stdout);  // the child must not write the parent's buffered output too
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (fd < 0 || ::dup2(fd, STDOUT_FILENO) < 0) ::_exit(2);
        std::printf("table\n");  // held in stdout's buffer: it is a file now
        try {
            write_file_atomically("/dev/stdout", "results\n", false);
            // The log under its own name is the process's stdout too: not renamed over, nor refused
            // as an existing file (`--json log > log`).
            check_output_file(log, false);
            write_file_atomically(log, "again\n", false);
        } catch (...) {
            ::_exit(3);
        }
        std::printf("after\n");
        std::fflush(stdout);
        // With stdout closed, /dev/stdout leads nowhere: refused, not made a file under /proc.
        ::close(STDOUT_FILENO);
        const std::string closed = test::error_of([] { check_output_file("/dev/stdout", true); });
        ::_exit(closed == "/dev/stdout: is not there (a closed stream?)" ? 0 : 4);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status)) << status;
    EXPECT_EQ(WEXITSTATUS(status), 0);
    std::ifstream written(log);
    EXPECT_EQ((std::string{std::istreambuf_iterator<char>(written), std::istreambuf_iterator<char>()}),
              "table\nresults\nagain\nafter\n");
    std::filesystem::remove(log);
}

// read_pfm reads only a regular file, as the loaders do: a folder or a named pipe in the image's place
// is refused with its name, not opened and waited on.
TEST(Render, ReadPfmRefusesWhatIsNotARegularFile) {
    const auto dir = std::filesystem::temp_directory_path() / ("cellrt_pfm_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto error_of = [](const std::string& path) { return test::error_of([&] { read_pfm(path); }); };
    const std::string folder = (dir / "folder.pfm").string(), fifo = (dir / "pipe.pfm").string();
    std::filesystem::create_directories(folder);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_EQ(error_of(folder), folder + ": is a folder, not a file");
    auto read = std::async(std::launch::async, [&] { return error_of(fifo); });
    if (read.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
        const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // the waiting reader's writer
        if (fd >= 0) ::close(fd);
        ADD_FAILURE() << "read_pfm waited on the pipe";
    }
    EXPECT_EQ(read.get(), fifo + ": is not a regular file (a pipe, socket or device)");
    EXPECT_EQ(error_of((dir / "absent.pfm").string()), (dir / "absent.pfm").string() + ": cannot open file for reading");
    const std::string truncated = (dir / "short.pfm").string();
    {
        std::ofstream out(truncated, std::ios::binary);
        out << "PF\n4 2\n-1\n" << std::string(12, '\0');
    }
    EXPECT_EQ(error_of(truncated), truncated + ": file is truncated");
    // Headers that are not a little-endian RGB PFM's, a greyscale or big-endian one among them, and a
    // file of no header at all, refused after at most 256 bytes of it.
    const std::string other = (dir / "other.pfm").string();
    const std::vector<std::string> headers{"Pf\n4 2\n-1\n", "PF\n4 2\n1\n", "PF\n4 x\n-1\n", "PF\n4 2\n",
                                           "P6\n4 2\n255\n", std::string(100000, 'A')};
    for (const std::string& header : headers) {
        {
            std::ofstream out(other, std::ios::binary | std::ios::trunc);
            out << header << std::string(96, '\0');
        }
        EXPECT_EQ(error_of(other), other + ": not a little-endian RGB PFM file") << header.substr(0, 20);
    }
    std::filesystem::remove_all(dir);
}

// A PNG from the frame's 8-bit pixels (what cellrt-mpi's ranks send) is the PNG of its floats, byte for
// byte; each byte is the channel's sRGB value, scaled and rounded, clamped at 0 and 1.
TEST(Render, PngOfEightBitPixelsIsThePngOfTheFloats) {
    const Scene scene = make_builtin_scene("builtin:spheres?tris=400");
    Image img = render_with(scene, "brute", 2, 20, 10);
    img.at(0, 0) = Vec3(-1.f, 2.f, 0.5f);
    const Srgb8Image bytes = to_srgb8(img);
    ASSERT_EQ(bytes.rgb.size(), 3u * 20 * 10);
    EXPECT_EQ(bytes.rgb[0], 0);
    EXPECT_EQ(bytes.rgb[1], 255);
    EXPECT_EQ(bytes.rgb[2], 188);  // 255 * (1.055 * 0.5^(1/2.4) - 0.055) = 187.5...
    EXPECT_EQ(bytes.rgb[3 * 13 + 1], srgb8(img.pixels[13].y));
    const auto dir = std::filesystem::temp_directory_path() / ("cellrt_png_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string floats = (dir / "floats.png").string(), eight = (dir / "eight.png").string();
    write_image(img, floats, false);
    write_png(bytes, eight, false);
    auto read = [](const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_FALSE(read(floats).empty());
    EXPECT_EQ(read(eight), read(floats));
    EXPECT_EQ(test::error_of([&] { write_png(bytes, eight, false); }), eight + ": file exists and overwrite is off");
    EXPECT_EQ(test::error_of([&] { write_png(bytes, (dir / "x.pfm").string(), false); }),
              (dir / "x.pfm").string() + ": 8-bit pixels are written as .png only");
    std::filesystem::remove_all(dir);
}

// An image is zero when made (ZeroedArray); copies are deep; a moved-from array is empty.
TEST(Render, ImagesAreZeroWhenMade) {
    const Image small(3, 2);
    ASSERT_EQ(small.pixels.size(), 6u);
    using Bits = std::array<std::uint32_t, 3>;
    for (const Vec3& p : small.pixels) EXPECT_EQ(std::bit_cast<Bits>(p), Bits{});  // +0, all bits zero
    Image a(5, 4);
    a.at(1, 2) = Vec3(1.f, 2.f, 3.f);
    Image b = a;
    EXPECT_TRUE(same_bits(a, b));
    b.at(1, 2).x = 7.f;
    EXPECT_EQ(a.at(1, 2).x, 1.f);
    EXPECT_FALSE(a.pixels == b.pixels);
    b = a;
    EXPECT_TRUE(a.pixels == b.pixels);
    const Image moved = std::move(b);
    EXPECT_TRUE(b.pixels.empty());  // NOLINT(bugprone-use-after-move): the moved-from state is specified
    EXPECT_TRUE(same_bits(moved, a));
    const Srgb8Image bytes(4, 4);
    EXPECT_TRUE(std::all_of(bytes.rgb.begin(), bytes.rgb.end(), [](std::uint8_t c) { return c == 0; }));
    // A frame of 4 MiB or more has a mapping of its own (2 MiB pages), a copy too.
    Image frame(1920, 1080);
    frame.at(0, 0) = frame.at(1919, 1079) = Vec3(0.5f);
    const Image copy = frame;
    EXPECT_TRUE(same_bits(copy, frame));
    EXPECT_EQ(copy.at(1919, 1079).y, 0.5f);
    EXPECT_EQ(copy.at(1918, 1079).y, 0.f);
    // A negative side is refused, not read as a size of 2^64 pixels.
    EXPECT_EQ(test::error_of([] { Image(-1, 5); }), "Image: image size -1x5: a side is negative");
    EXPECT_EQ(test::error_of([] { Srgb8Image(5, -1); }), "Srgb8Image: image size 5x-1: a side is negative");
    EXPECT_TRUE(Image(0, 3).pixels.empty());
    Image wrong(2, 2);
    wrong.width = 1;  // fields set by hand: four pixels named 1x2
    EXPECT_EQ(test::error_of([&] { to_srgb8(wrong); }), "to_srgb8: an image of 4 pixels is not 1x2");
}

// ... and its memory untouched until written: a frame's pages are faulted in by the workers that
// write them, not zeroed on one thread before the render. A 1080p frame's 25 MB: none of its pages
// resident once made.
TEST(Render, AFramesMemoryIsUntouchedWhenMade) {
    CELLRT_SKIP_UNDER_SANITIZERS("their runtimes manage the memory (AddressSanitizer: every block from its allocator)");
    const Image frame(1920, 1080);
    const long page = ::sysconf(_SC_PAGESIZE);
    const auto begin = reinterpret_cast<std::uintptr_t>(frame.pixels.data());
    const std::uintptr_t first = (begin + page - 1) / page * page;
    const std::uintptr_t end = (begin + frame.pixels.size() * sizeof(Vec3)) / page * page;
    std::vector<unsigned char> resident((end - first) / page);
    ASSERT_EQ(::mincore(reinterpret_cast<void*>(first), end - first, resident.data()), 0);
    EXPECT_EQ(std::count_if(resident.begin(), resident.end(), [](unsigned char r) { return r & 1; }), 0);
    EXPECT_EQ(frame.at(1919, 1079).z, 0.f);  // read as zero (the kernel's zero page)
}

// The table gives the formula's byte (every float of [0, 1] is checked by docs/figures/srgb8_check.cpp;
// here the ends, the values outside [0, 1], a million floats of it at random and the floats next to
// each byte's first).
TEST(Render, Srgb8TableGivesTheFormulasBytes) {
    for (const float x : {0.f, -0.f, 1.f, -1.f, 2.f, 1e30f, -1e-30f, std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::denorm_min(),
                          std::numeric_limits<float>::min(), 0.0031308f, 0.5f, std::nextafter(1.f, 0.f)})
        EXPECT_EQ(srgb8(x), srgb8_exact(x)) << x;
    EXPECT_EQ(srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
    std::uint32_t state = 12345;
    int changes = 0;
    for (int i = 0; i < 1000000; ++i) {
        state = state * 1664525u + 1013904223u;
        const float x = std::bit_cast<float>(state % 0x3F800001u);
        ASSERT_EQ(srgb8(x), srgb8_exact(x)) << x;
    }
    for (int k = 1; k < 256; ++k) {
        std::uint32_t lo = 0, hi = 0x3F800000u;  // the least float whose byte is k or more
        while (lo < hi) {
            const std::uint32_t mid = lo + (hi - lo) / 2;
            if (srgb8_exact(std::bit_cast<float>(mid)) >= k) hi = mid;
            else lo = mid + 1;
        }
        for (std::uint32_t b = lo - std::min(lo, 64u); b <= lo + 64; ++b)
            ASSERT_EQ(srgb8(std::bit_cast<float>(b)), srgb8_exact(std::bit_cast<float>(b))) << k;
        changes += srgb8_exact(std::bit_cast<float>(lo)) == k;
    }
    EXPECT_EQ(changes, 255);  // each byte is reached
}

// Image sizes, as text and as numbers: both sides in [1, 65536], at most 2^28 pixels, refused in the
// library's words before any pixel is allocated (render, read_pfm).
TEST(ImageSize, ParsedStrictlyAndLimitedBeforeAllocation) {
    using test::error_of;
    EXPECT_EQ(parse_image_size("--size", "1920x1080"), (std::pair<int, int>{1920, 1080}));
    EXPECT_EQ(parse_image_size("--size", "65536x4096"), (std::pair<int, int>{65536, 4096}));
    EXPECT_EQ(parse_image_size("--size", "16384x16384"), (std::pair<int, int>{16384, 16384}));
    for (const std::string bad : {"", "x", "10", "10x", "x10", " 10x10", "10x10 ", "+10x10", "10x+10", "10X10",
                                  "10x10x1", "1e3x10", "10.5x10", "0x10.0"})
        EXPECT_EQ(error_of([&] { parse_image_size("--size", bad); }),
                  "--size '" + bad + "' must be WIDTHxHEIGHT (two whole numbers, e.g. 1920x1080)");
    for (const std::string bad : {"0x5", "5x0", "-1x5", "65537x1", "4294967297x10", "99999999999999999999x1",
                                  "-99999999999999999999x1"})
        EXPECT_EQ(error_of([&] { parse_image_size("--size", bad); }),
                  "--size '" + bad + "' must have both sides in [1, 65536]");
    EXPECT_EQ(error_of([&] { parse_image_size("--size", "65536x65536"); }),
              "--size '65536x65536' has 4294967296 pixels, more than the largest image's 268435456");
    EXPECT_EQ(error_of([] { check_image_size(16385, 16384); }),
              "image size 16385x16384 has 268451840 pixels, more than the largest image's 268435456");
    EXPECT_EQ(error_of([] { check_image_size(-3, 4); }), "image size -3x4 must have both sides in [1, 65536]");

    const Scene scene = make_builtin_scene("builtin:spheres?tris=400");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"kd"});
    RenderOptions o;
    o.width = o.height = 65536;
    EXPECT_EQ(error_of([&] { render(scene, *accel, o); }),
              "image size 65536x65536 has 4294967296 pixels, more than the largest image's 268435456");

    const auto dir = std::filesystem::temp_directory_path() / ("cellrt_test_size_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "huge.pfm").string();
    std::ofstream(path, std::ios::binary) << "PF\n100000 100000\n-1.0\n";
    EXPECT_EQ(error_of([&] { read_pfm(path); }),
              path + ": image size 100000x100000 must have both sides in [1, 65536]");
    std::ofstream(path, std::ios::binary) << "PF\n99999999999 2\n-1.0\n";
    EXPECT_EQ(error_of([&] { read_pfm(path); }), path + ": not a little-endian RGB PFM file");

    // Written images pass the same check, and hold the pixels their size says: an empty image made a
    // PFM read_pfm refused and a PNG of no pixels; one whose pixels were missing was read past.
    const std::string out = (dir / "out.pfm").string(), png = (dir / "out.png").string();
    EXPECT_EQ(error_of([&] { write_image(Image(), out, false); }),
              out + ": image size 0x0 must have both sides in [1, 65536]");
    EXPECT_EQ(error_of([&] { write_png(Srgb8Image(), png, false); }),
              png + ": image size 0x0 must have both sides in [1, 65536]");
    Image missing;
    missing.width = missing.height = 4;
    EXPECT_EQ(error_of([&] { write_image(missing, png, false); }), png + ": the image is 4x4 but holds 0 pixels");
    Srgb8Image short_rows(2, 2);
    short_rows.height = 3;
    EXPECT_EQ(error_of([&] { write_png(short_rows, png, false); }), png + ": the image is 2x3 but holds 4 pixels");
    EXPECT_FALSE(std::filesystem::exists(out) || std::filesystem::exists(png));
    std::filesystem::remove_all(dir);
}

// Found by audit (2026-12-07): a scene made in code with a NaN or negative light colour rendered NaN
// or negative pixels, and render() from a progress callback waited for ever.
TEST(Render, ABadLightOrAFrameInsideAFrameIsRefused) {
    Scene scene = make_builtin_scene("builtin:spheres?tris=200");
    const auto accel = make_accelerator(scene.triangles, AccelConfig{"kd"});
    RenderOptions options;
    options.width = options.height = 16;
    scene.light.color = {std::nanf(""), 1.f, 1.f};
    EXPECT_EQ(test::error_of([&] { render(scene, *accel, options); }), "the light color is not finite");
    scene.light.color = {-5.f, -5.f, -5.f};
    EXPECT_EQ(test::error_of([&] { render(scene, *accel, options); }), "the light color has a negative channel");
    scene.light.color = {1.f, 1.f, 1.f};
    scene.light.position = {std::nanf(""), 0.f, 0.f};
    EXPECT_EQ(test::error_of([&] { render(scene, *accel, options); }), "the light position is not finite");
    scene.light.position = {0.f, 10.f, 0.f};
    const std::string nested = "a frame was started from inside a frame (a progress callback or a packet's trace): "
                               "frames run one at a time on the process's one team of workers";
    for (const Dispatch d : {Dispatch::pull, Dispatch::mailbox})
        for (const unsigned threads : {1u, 2u}) {
            options.dispatch = d;
            options.threads = threads;
            options.progress = [&](std::size_t, std::size_t) { render(scene, *accel, RenderOptions{}); };
            EXPECT_EQ(test::error_of([&] { render(scene, *accel, options); }), nested) << threads;
        }
    options.progress = nullptr;
    EXPECT_EQ(render(scene, *accel, options).width, 16);  // the team still works
}

TEST(Render, ShadowOriginLeavesTheSurface) {
    // A hit point pushed along its normal lies strictly on the normal side, by at least 2^-18 of the
    // largest magnitude it was made from (2^-16 near the origin).
    for (const Vec3 p : {Vec3{1000.f, 2.f, -3.f}, Vec3{0.001f, 0.f, 0.f}, Vec3{-12345.f, 678.f, 0.5f}}) {
        const SurfacePoint sp{p, {0.f, 1.f, 0.f}, max_magnitude(p)};
        const Vec3 o = offset_ray_origin(sp);
        EXPECT_GE(o.y - p.y, std::fmax(max_magnitude(p) * 0x1p-18f, 0x1p-16f) * 0.999f);
        EXPECT_EQ(o.x, p.x);
    }
}

// Rays leaving a ground of two huge triangles never hit it (found by audit, 2026-12-07: with an
// offset of 256 ulps of the hit point, AO and shadow rays leaving a ground 10 km wide near its middle
// hit it again, about half of those under 45 degrees, since the test of a ray against a triangle errs
// by ulps of the triangle's corners); and a light just inside a closed box lights nothing outside.
TEST(Render, SecondaryRaysLeaveHugeTrianglesAndStopAtWallsNearTheLight) {
    for (const float half : {5000.f, 450.f, 5.f}) {
        const std::vector<Triangle> ground{{{-half, 0.f, -half}, {half, 0.f, -half}, {half, 0.f, half}},
                                           {{-half, 0.f, -half}, {half, 0.f, half}, {-half, 0.f, half}}};
        const auto accel = make_accelerator(ground, AccelConfig{"brute"});
        std::vector<Ray> leaving;
        for (int i = 0; i < 2000; ++i) {
            // Camera rays from above onto points near the middle, each hit's ray leaving at an angle
            // from grazing (0.01 rad) to steep.
            const float x = 0.16f * static_cast<float>(i % 50) - 4.f, z = 0.2f * static_cast<float>(i / 50) - 4.f;
            Ray down;
            down.org = {x, 3.f, z};
            down.dir = {0.01f, -1.f, 0.02f};
            std::vector<Hit> hit(1);
            accel->intersect(std::span(&down, 1), hit);
            ASSERT_TRUE(hit[0].is_hit());
            const SurfacePoint sp = surface_point(ground[hit[0].prim], down, hit[0]);
            const float angle = 0.01f + 1.5f * static_cast<float>(i % 97) / 97.f, turn = 0.7f * static_cast<float>(i);
            Ray out;
            out.org = offset_ray_origin(sp);
            out.dir = {std::cos(angle) * std::cos(turn), std::sin(angle), std::cos(angle) * std::sin(turn)};
            leaving.push_back(out);
            leaving.push_back(shadow_ray(sp, out.org + out.dir * 100.f));
        }
        std::vector<std::uint8_t> blocked(leaving.size());
        accel->occluded(leaving, blocked);
        EXPECT_EQ(std::count(blocked.begin(), blocked.end(), std::uint8_t{1}), 0) << "a ground " << 2 * half << " wide";
    }
    // A closed box 2 wide around the origin, the light 1e-3 inside its +x wall, a point 20 away (the
    // shadow ray stops 2^-18 of 21 short of the light, 8e-5; 1e-4 of the distance was 2e-3).
    const Vec3 lo{-1.f, -1.f, -1.f}, hi{1.f, 1.f, 1.f};
    std::vector<Triangle> box;
    for (int a = 0; a < 3; ++a)
        for (const float side : {lo[a], hi[a]}) {
            Vec3 c[4];
            for (int k = 0; k < 4; ++k) {
                c[k][a] = side;
                c[k][(a + 1) % 3] = (k == 1 || k == 2) ? hi[(a + 1) % 3] : lo[(a + 1) % 3];
                c[k][(a + 2) % 3] = (k >= 2) ? hi[(a + 2) % 3] : lo[(a + 2) % 3];
            }
            box.push_back({c[0], c[1], c[2]});
            box.push_back({c[0], c[2], c[3]});
        }
    const auto closed = make_accelerator(box, AccelConfig{"brute"});
    const SurfacePoint outside{{21.f, 0.3f, 0.2f}, {-1.f, 0.f, 0.f}, 21.f};
    const Ray shadow = shadow_ray(outside, Vec3{0.999f, 0.f, 0.f});
    std::vector<std::uint8_t> blocked(1);
    closed->occluded(std::span(&shadow, 1), blocked);
    EXPECT_EQ(blocked[0], 1) << "the light leaked out of the box";
}

}  // namespace
}  // namespace cellrt
