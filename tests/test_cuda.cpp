// The CUDA backend on a GPU: every tree and traversal returns exactly the brute-force hits through
// host batches and resident batches, counts the host's work, and `render --device cuda` writes the
// CPU's image. These tests need a device and show as SKIPPED without one (CI has none; docs/GPU.md);
// what the backend says without a device, or without CUDA in the build, is tested everywhere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

#include "accel/local_store_registry.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/device.hpp"
#include "cellrt/error.hpp"
#include "cellrt/image.hpp"
#include "cellrt/render.hpp"
#include "cellrt/workload.hpp"
#include "error_of.hpp"
#include "ray_suite.hpp"
#include "structure_cases.hpp"

namespace cellrt {
namespace {

namespace fs = std::filesystem;

bool have_gpu() { return cuda_device_info().present; }

#define REQUIRE_GPU()                                                                                   \
    do {                                                                                                \
        if (!have_gpu()) GTEST_SKIP() << "no CUDA device: " << cuda_device_info().reason;              \
    } while (0)

// The program's output and exit status; CELLRT_CLI in the environment names the program where the
// tests run from a bundle (tools/device-check.sh).
std::pair<std::string, int> run_cli(const std::string& args) {
    const char* env = std::getenv("CELLRT_CLI");
    FILE* p = ::popen((std::string(env ? env : CELLRT_CLI) + " " + args + " 2>&1").c_str(), "r");
    if (!p) return {"", -1};
    std::string out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    const int status = ::pclose(p);
    return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

AccelConfig cuda_config(const std::string& spec) {
    AccelConfig c = parse_accel_config(spec);
    c.device = "cuda";
    return c;
}

const std::vector<std::string> kCudaConfigs = {"kd:branched", "kd:rec",          "kd:branchless",
                                               "bih:branched", "bih:branchless", "bih:branched@split=sah"};

TEST(CudaInfo, NamesTheDeviceOrSaysInOneLineThatThereIsNone) {
    const DeviceInfo d = cuda_device_info();
    const auto [out, status] = run_cli("info --device cuda");
    if (d.present) {
        EXPECT_EQ(status, 0) << out;
        EXPECT_NE(out.find(d.name), std::string::npos) << out;
    } else {
        EXPECT_FALSE(d.reason.empty());
        EXPECT_EQ(status, 3) << out;
        EXPECT_EQ(out, "cuda: no device (" + d.reason + ")\n");
    }
}

// Kinds, SIMD packets and devices the backend does not take are refused with a reason, device or not.
TEST(CudaRefusals, InTheLibrarysWords) {
    const std::vector<Triangle> tri = {{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}}};
    AccelConfig bad_device = parse_accel_config("kd");
    bad_device.device = "tpu";
    EXPECT_EQ(test::error_of([&] { make_accelerator(tri, bad_device); }), "device 'tpu' is not one of: cpu, cuda");
    for (const std::string spec : {"bvh", "brute", "kd+avx2"}) {
        const std::string e = test::error_of([&] { make_accelerator(tri, cuda_config(spec)); });
        EXPECT_NE(e, "no error") << spec;
        EXPECT_EQ(e.find('\n'), std::string::npos) << spec << ": " << e;
    }
    if (!have_gpu()) {
        const std::string e = test::error_of([&] { make_accelerator(tri, cuda_config("kd")); });
        EXPECT_EQ(e, "device 'cuda': " + cuda_device_info().reason);
        EXPECT_NE(test::error_of([&] { DeviceRayBatch batch(16); }), "no error");
        const fs::path image = fs::temp_directory_path() / ("cellrt_cuda_refused_" + std::to_string(::getpid()) + ".png");
        const auto [out, status] =
            run_cli("render builtin:spheres?tris=200 --size 8x8 --device cuda -o " + image.string());
        EXPECT_EQ(status, 1) << out;
        EXPECT_FALSE(fs::exists(image));
        EXPECT_EQ(out, "cellrt: error: device 'cuda': " + cuda_device_info().reason + "\n");
    }
}

// Memory mode (b)'s parameters are read before any device is needed: a bad layout is refused in one
// line on any machine with the CUDA backend built.
TEST(CudaRefusals, SharedMemoryLayouts) {
    const std::vector<Triangle> tri = {{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}}};
    auto expect_refused = [&](std::map<std::string, std::string> params, const std::string& why) {
        AccelConfig c = cuda_config("kd");
        c.params = std::move(params);
        const std::string e = test::error_of([&] { make_accelerator(tri, c); });
#ifdef CELLRT_HAVE_CUDA
        EXPECT_EQ(e, why);
#else
        EXPECT_EQ(e, "device 'cuda': " + cuda_device_info().reason) << why;
#endif
    };
    expect_refused({{"memory", "shared"}, {"node_line", "48"}}, "cuda parameter node_line=48: a line is a power of two bytes");
    expect_refused({{"triangle_ways", "4"}},
                   "cuda parameter triangle_ways=4 shapes the shared-memory caches: it needs memory=shared");
}

// `cache-study --device cuda` checks its options before it looks for the device, and without one it
// fails in one line and writes nothing.
TEST(CudaRefusals, CacheStudyOnTheDevice) {
    const fs::path dir = fs::temp_directory_path() / ("cellrt_cuda_study_" + std::to_string(::getpid()));
    const std::string study = "cache-study builtin:spheres?tris=200 --size 16x16 -o " + dir.string() + " --device ";
    const auto [other, other_status] = run_cli(study + "tpu");
    EXPECT_EQ(other_status, 1) << other;
    EXPECT_EQ(other, "cellrt: error: --device 'tpu' is not one of: cpu, cuda\n");
    const auto [bad, bad_status] = run_cli(study + "cuda --access dma");
    EXPECT_EQ(bad_status, 1) << bad;
    EXPECT_NE(bad.find("--access"), std::string::npos) << bad;
    if (!have_gpu())
        for (const char* access : {"", " --access async"}) {
            const auto [out, status] = run_cli(study + "cuda" + access);
            EXPECT_EQ(status, 1) << out;
            EXPECT_EQ(out, "cellrt: error: --device cuda: no device (" + cuda_device_info().reason + ")\n");
        }
    EXPECT_FALSE(fs::exists(dir));
}

// The study's sweeps on the GPU: one CSV row per run, as the model writes, each run's lookups those of
// the model's run with the same layouts and access (a read's lookups depend on its address and size
// only; touches are counted apart), its time measured (frame_ms) and none modelled (cycles 0).
TEST(CudaCacheStudy, SameRunsAndLookupsAsTheModel) {
    REQUIRE_GPU();
    const fs::path dir = fs::temp_directory_path() / ("cellrt_cuda_study_" + std::to_string(::getpid()));
    const std::string study = "cache-study builtin:spheres?tris=2000 --size 64x64 --sample 1 --structures kd bih "
                              "--traversals branched --access sync async --overwrite -o ";
    for (const char* device : {"cpu", "cuda"}) {
        const auto [out, status] = run_cli(study + (dir / device).string() + " --device " + device);
        ASSERT_EQ(status, 0) << out;
    }
    auto rows = [&](const char* device) {
        std::ifstream in(dir / device / "cache_study.csv");
        std::vector<std::vector<std::string>> out;
        for (std::string line; std::getline(in, line);) {
            std::vector<std::string> cells;
            std::stringstream fields(line);
            for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
            out.push_back(cells);
        }
        return out;
    };
    const auto cpu = rows("cpu"), gpu = rows("cuda");
    ASSERT_EQ(gpu.size(), cpu.size());
    ASSERT_GT(gpu.size(), 1u);
    EXPECT_EQ(gpu[0], cpu[0]);  // the header
    const auto& h = cpu[0];
    auto at = [&](const std::vector<std::string>& row, const std::string& column) {
        return row[static_cast<std::size_t>(std::find(h.begin(), h.end(), column) - h.begin())];
    };
    for (std::size_t i = 1; i < gpu.size(); ++i) {
        for (const char* same : {"structure", "access", "sweep", "node_layout", "tri_layout", "rays"})
            EXPECT_EQ(at(gpu[i], same), at(cpu[i], same)) << "row " << i << " " << same;
        for (const char* cache : {"node", "tri"}) {
            const std::string c(cache);
            EXPECT_EQ(std::stoull(at(gpu[i], c + "_hits")) + std::stoull(at(gpu[i], c + "_misses")),
                      std::stoull(at(cpu[i], c + "_hits")) + std::stoull(at(cpu[i], c + "_misses")))
                << "row " << i << " " << c << " lookups";
        }
        EXPECT_EQ(at(gpu[i], "cycles"), "0");
        EXPECT_GT(std::stod(at(gpu[i], "frame_ms")), 0.0) << "row " << i;
    }
    fs::remove_all(dir);
}

class CudaAgainstBruteForce : public testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(CudaAgainstBruteForce, SameHits) {
    REQUIRE_GPU();
    const auto& [scene_name, spec] = GetParam();
    const Scene* scene = test::structure_scene(scene_name);
    if (!scene) GTEST_SKIP() << "scene " << scene_name << " not found under " << test::scenes_dir();
    const test::ReferenceAnswers& ref = test::cached_reference(scene_name, scene->triangles);
    test::expect_matches(*make_accelerator(scene->triangles, cuda_config(spec)), ref, "cuda " + spec + " on " + scene_name);
}

INSTANTIATE_TEST_SUITE_P(Scenes, CudaAgainstBruteForce,
                         testing::Combine(testing::ValuesIn(test::structure_scene_names()), testing::ValuesIn(kCudaConfigs)),
                         [](const auto& info) {
                             std::string s = test::test_name(std::get<0>(info.param)) + "_" + std::get<1>(info.param);
                             for (char& c : s)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return s;
                         });

TEST(CudaDegenerate, SameHitsAsBruteForce) {
    REQUIRE_GPU();
    for (const auto& [what, tris] : test::degenerate_scenes()) {
        const test::ReferenceAnswers ref = test::reference_suite(tris, test::small_suite());
        for (const std::string& spec : kCudaConfigs)
            test::expect_matches(*make_accelerator(tris, cuda_config(spec)), ref, "cuda " + spec + " on " + what);
    }
}

TEST(CudaDegenerate, EmptySceneAndEmptyBatches) {
    REQUIRE_GPU();
    const std::vector<Triangle> none;
    const std::vector<Ray> rays = {{{0.f, 0.f, 0.f}, 0.f, {1.f, 0.f, 0.f}, kInfinity}};
    for (const std::string& spec : kCudaConfigs) {
        const auto accel = make_accelerator(none, cuda_config(spec));
        std::vector<Hit> hits(1);
        std::vector<std::uint8_t> occluded(1, 2);
        accel->intersect(rays, hits);
        accel->occluded(rays, occluded);
        EXPECT_FALSE(hits[0].is_hit()) << spec;
        EXPECT_EQ(occluded[0], 0) << spec;
        accel->intersect({}, {});
        EXPECT_THROW(accel->intersect(rays, {}), Error) << spec;
    }
}

// Resident batches give the host batches' answers, and the device counts the host's work exactly.
TEST(CudaResident, SameAnswersAndWorkAsTheHost) {
    REQUIRE_GPU();
    const Scene& scene = test::cached_scene("builtin:city?tris=20000");
    const test::ReferenceAnswers& ref = test::cached_reference("builtin:city?tris=20000", scene.triangles);
    for (const std::string& spec : kCudaConfigs) {
        const auto device = make_device_accelerator(scene.triangles, cuda_config(spec));
        DeviceRayBatch batch(ref.rays.size());
        batch.upload(ref.rays);
        TraversalCounters on_device, on_host;
        EXPECT_GT(device->intersect_resident(batch, &on_device), 0.0);
        std::vector<Hit> hits(ref.rays.size());
        batch.download_hits(hits);
        EXPECT_TRUE(hits == ref.hits) << spec;
        device->occluded_resident(batch);
        std::vector<std::uint8_t> occluded(ref.rays.size());
        batch.download_occluded(occluded);
        EXPECT_TRUE(occluded == ref.occluded) << spec;
        make_accelerator(scene.triangles, parse_accel_config(spec))->intersect(ref.rays, hits, &on_host);
        EXPECT_EQ(on_device.rays, on_host.rays) << spec;
        EXPECT_EQ(on_device.nodes, on_host.nodes) << spec;
        EXPECT_EQ(on_device.leaves, on_host.leaves) << spec;
        EXPECT_EQ(on_device.triangles, on_host.triangles) << spec;
        EXPECT_THROW(batch.upload(std::vector<Ray>(ref.rays.size() + 1)), Error);
    }
}

// Memory mode (b): through the blocks' shared-memory caches every tree and traversal returns the
// brute-force hits; the blocks look up exactly the lines the local-store model looks up for the same
// reads (a read's lookups depend only on its address and size), whatever the interleaving of the
// block's threads makes of hits and misses.
TEST(CudaSharedMemory, SameHitsAndLookupsAsTheModel) {
    REQUIRE_GPU();
    const std::string name = "builtin:city?tris=20000";
    const Scene& scene = test::cached_scene(name);
    const test::ReferenceAnswers& ref = test::cached_reference(name, scene.triangles);
    for (const std::string& spec : kCudaConfigs) {
        for (const auto& [ways, access] : {std::pair{"1", "sync"}, std::pair{"4", "sync"}, std::pair{"1", "async"},
                                           std::pair{"4", "async"}}) {
            AccelConfig c = cuda_config(spec);
            c.params.insert({{"memory", "shared"}, {"access", access}, {"node_line", "64"}, {"node_sets", "64"},
                             {"node_ways", ways}, {"triangle_line", "128"}, {"triangle_sets", "32"},
                             {"triangle_ways", ways}});
            const std::string what = "cuda " + spec + " memory=shared ways " + ways + " access " + access;
            const auto device = make_device_accelerator(scene.triangles, c);
            test::expect_matches(*device, ref, what);
            const DeviceCacheStats before = device->cache_stats();
            std::vector<Hit> hits(ref.rays.size());
            device->intersect(ref.rays, hits);
            const DeviceCacheStats s = device->cache_stats();
            EXPECT_TRUE(hits == ref.hits) << what;
            LocalStoreConfig model_config;
            model_config.node_cache = {64, 64, static_cast<std::uint32_t>(std::stoi(ways))};
            model_config.triangle_cache = {128, 32, static_cast<std::uint32_t>(std::stoi(ways))};
            AccelConfig cpu = parse_accel_config(spec);
            const auto model = make_local_store_accelerator(scene.triangles, cpu, model_config);
            model->intersect(ref.rays, hits);
            const LocalStoreStats m = model->local_store_stats();
            EXPECT_EQ(s.node_cache.lookups() - before.node_cache.lookups(), m.node_cache.hits + m.node_cache.misses)
                << what;
            EXPECT_EQ(s.triangle_cache.lookups() - before.triangle_cache.lookups(),
                      m.triangle_cache.hits + m.triangle_cache.misses)
                << what;
            EXPECT_GT(s.node_cache.hits, 0u) << what;
            EXPECT_GT(s.blocks, before.blocks) << what;
            if (access == std::string("async")) {
                EXPECT_GT(s.node_cache.prefetches, 0u) << what;
            } else {
                EXPECT_EQ(s.node_cache.prefetches + s.node_cache.touch_hits, 0u) << what;
            }
            const auto& settings = device->stats().settings;
            EXPECT_TRUE(std::any_of(settings.begin(), settings.end(), [](const auto& kv) {
                return kv.first == "memory" && kv.second.rfind("shared: ", 0) == 0;
            })) << what;
        }
    }
}

// A layout over the device's shared memory per block is refused in one line.
TEST(CudaSharedMemory, CachesOverTheBudgetAreRefused) {
    REQUIRE_GPU();
    const std::vector<Triangle> tri = {{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}}};
    AccelConfig c = cuda_config("bih");
    c.params = {{"memory", "shared"}, {"node_line", "4096"}, {"node_sets", "64"}};
    const std::string e = test::error_of([&] { make_accelerator(tri, c); });
    EXPECT_NE(e.find("B of shared memory a block of this device has"), std::string::npos) << e;
}

// `render --device cuda` writes the CPU's image, bit for bit, under every shading.
TEST(CudaRender, SameImageAsTheCpu) {
    REQUIRE_GPU();
    const fs::path dir = fs::temp_directory_path() / ("cellrt_cuda_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    for (const char* shading : {"direct", "ao --ao-samples 3", "diffuse"}) {
        auto render = [&](const std::string& name, const std::string& extra) {
            const fs::path out = dir / (name + ".pfm");
            const auto [text, status] = run_cli("render builtin:spheres?tris=3000 --size 67x45 --overwrite --shading " +
                                                std::string(shading) + " " + extra + " -o " + out.string());
            EXPECT_EQ(status, 0) << text;
            return read_pfm(out.string());
        };
        const Image cpu = render("cpu", "--accel kd");
        for (const char* accel : {"kd", "bih"}) {
            const Image gpu = render(std::string("gpu_") + accel, std::string("--device cuda --accel ") + accel);
            ASSERT_EQ(gpu.pixels.size(), cpu.pixels.size());
            EXPECT_EQ(std::memcmp(gpu.pixels.data(), cpu.pixels.data(), cpu.pixels.size() * sizeof(Vec3)), 0)
                << accel << " " << shading;
        }
    }
    fs::remove_all(dir);
}

// The frame path through the library: on every scene of the structure tests, both trees and both
// memory modes, the three shadings, whole frames and a window of one (a distributed frame's tile) are
// the CPU renderer's pixels bit for bit, with as many rays.
TEST(CudaFrame, SameImageAndRaysAsTheCpuOnEveryScene) {
    REQUIRE_GPU();
    for (const std::string& name : test::structure_scene_names()) {
        const Scene* scene = test::structure_scene(name);
        if (!scene) continue;
        const auto cpu = make_accelerator(scene->triangles, parse_accel_config("kd"));
        const PixelRect window{13, 9, 150, 101};
        struct Expected {
            RenderOptions options;
            Image image, tile;
            RenderStats stats;
        };
        std::vector<Expected> expected;
        for (const ShadingOptions shading : {ShadingOptions{Shading::direct, 4}, ShadingOptions{Shading::ao, 5},
                                             ShadingOptions{Shading::diffuse, 4}}) {
            Expected e;
            e.options.width = 203;
            e.options.height = 117;
            e.options.shading = shading;
            render(*scene, *cpu, e.options, e.image, &e.stats);
            render_window(*scene, *cpu, e.options, window, e.tile);
            expected.push_back(std::move(e));
        }
        for (const std::string spec : {"kd:branched", "bih:branchless", "kd:rec@memory=shared", "bih:branched@memory=shared"}) {
            const auto gpu = make_accelerator(scene->triangles, cuda_config(spec));
            for (const Expected& e : expected) {
                const std::string what = spec + ", " + to_string(e.options.shading.shading) + " on " + name;
                RenderStats stats;
                const Image image = render(*scene, *gpu, e.options, &stats);
                ASSERT_EQ(image.pixels.size(), e.image.pixels.size()) << what;
                EXPECT_EQ(std::memcmp(image.pixels.data(), e.image.pixels.data(), image.pixels.size() * sizeof(Vec3)), 0)
                    << what;
                EXPECT_EQ(stats.primary_rays, e.stats.primary_rays) << what;
                EXPECT_EQ(stats.secondary_rays, e.stats.secondary_rays) << what;
                Image tile;
                render_window(*scene, *gpu, e.options, window, tile);
                ASSERT_EQ(tile.pixels.size(), e.tile.pixels.size()) << what;
                EXPECT_EQ(std::memcmp(tile.pixels.data(), e.tile.pixels.data(), tile.pixels.size() * sizeof(Vec3)), 0)
                    << what << ", window";
            }
        }
    }
}

// The work a frame's rays do on the device is the host's for the same kernel: counted in the
// renderer's statistics when asked.
TEST(CudaFrame, CountsTheHostsWork) {
    REQUIRE_GPU();
    const Scene& scene = test::cached_scene("builtin:city?tris=20000");
    RenderOptions ro;
    ro.width = 96;
    ro.height = 64;
    ro.count = true;
    ro.shading.shading = Shading::diffuse;
    AccelConfig host = parse_accel_config("bih:branched");
    host.simd = "off";
    RenderStats cpu_stats, gpu_stats;
    render(scene, *make_accelerator(scene.triangles, host), ro, &cpu_stats);
    render(scene, *make_accelerator(scene.triangles, cuda_config("bih:branched")), ro, &gpu_stats);
    EXPECT_EQ(gpu_stats.primary.rays, cpu_stats.primary.rays);
    EXPECT_EQ(gpu_stats.primary.nodes, cpu_stats.primary.nodes);
    EXPECT_EQ(gpu_stats.primary.triangles, cpu_stats.primary.triangles);
    EXPECT_EQ(gpu_stats.secondary.rays, cpu_stats.secondary.rays);
    EXPECT_EQ(gpu_stats.secondary.nodes, cpu_stats.secondary.nodes);
    EXPECT_EQ(gpu_stats.secondary.triangles, cpu_stats.secondary.triangles);
}

// What the device accelerator's frame call refuses, in one line each.
TEST(CudaFrame, RefusesAWindowOrTrianglesThatDoNotFit) {
    REQUIRE_GPU();
    const Scene& scene = test::cached_scene("builtin:spheres?tris=2000");
    const auto gpu = make_device_accelerator(scene.triangles, cuda_config("kd"));
    const FrameShading frame = frame_shading(scene, PinholeCamera(scene.camera, 16, 16), {});
    std::vector<Vec3> pixels(16 * 16);
    TraversalCounters p, s;
    EXPECT_EQ(test::error_of([&] { gpu->render_frame(scene.triangles, frame, 0, 0, 0, 16, pixels, p, s); }),
              "device frame: the window 0x16 at (0, 0) is empty");
    EXPECT_EQ(test::error_of([&] { gpu->render_frame(scene.triangles, frame, 0, 0, 16, 8, pixels, p, s); }),
              "device frame: 256 pixels given for the window 16x8 at (0, 0)");
    EXPECT_EQ(test::error_of([&] {
                  gpu->render_frame(std::span(scene.triangles).first(10), frame, 0, 0, 16, 16, pixels, p, s);
              }),
              "device frame: 10 triangles given for a tree built over " + std::to_string(scene.triangles.size()));
}

}  // namespace
}  // namespace cellrt
