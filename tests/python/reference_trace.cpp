// The C++ side of the Python module's bit-for-bit tests (tests/python/test_against_cpp.py), without
// the bindings: reads a scene, an accelerator spec and raw rays, traces them in one call of the public
// API and writes the raw answers.
//
//   cellrt_py_reference SCENE SPEC RAYS OUT closest|any
//   cellrt_py_reference SCENE camera WIDTHxHEIGHT OUT
//
// RAYS: the Ray records (32 bytes each: origin, tnear, direction, tfar, float32). OUT: the Hit records
// (16 bytes: t, prim as uint32, u, v) for closest, one byte per ray for any; with `camera`, the Ray
// records of the scene camera's primary rays, row-major from the top row.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/image.hpp"
#include "cellrt/error.hpp"
#include "cellrt/scene.hpp"

int main(int argc, char** argv) {
    if (argc != 6 && !(argc == 5 && std::string(argv[2]) == "camera")) {
        std::fprintf(stderr, "usage: cellrt_py_reference SCENE SPEC RAYS OUT closest|any | SCENE camera WxH OUT\n");
        return 2;
    }
    try {
        const cellrt::Scene scene = cellrt::load_scene(argv[1]);
        if (argc == 5) {
            const auto [w, h] = cellrt::parse_image_size("size", argv[3]);
            const cellrt::PinholeCamera camera(scene.camera, w, h);
            std::vector<cellrt::Ray> rays;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) rays.push_back(camera.primary(x, y));
            std::ofstream out(argv[4], std::ios::binary);
            out.write(reinterpret_cast<const char*>(rays.data()), static_cast<std::streamsize>(rays.size() * sizeof(cellrt::Ray)));
            return out ? 0 : 1;
        }
        const auto accel = cellrt::make_accelerator(scene.triangles, cellrt::parse_accel_config(argv[2]));
        std::ifstream in(argv[3], std::ios::binary);
        const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        if (!in || bytes.size() % sizeof(cellrt::Ray) != 0) throw cellrt::Error(std::string(argv[3]) + ": not Ray records");
        std::vector<cellrt::Ray> rays(bytes.size() / sizeof(cellrt::Ray));
        std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(rays.data()));
        std::ofstream out(argv[4], std::ios::binary);
        if (std::string(argv[5]) == "closest") {
            std::vector<cellrt::Hit> hits(rays.size());
            accel->intersect(rays, hits);
            out.write(reinterpret_cast<const char*>(hits.data()), static_cast<std::streamsize>(hits.size() * sizeof(cellrt::Hit)));
        } else {
            std::vector<std::uint8_t> occluded(rays.size());
            accel->occluded(rays, occluded);
            out.write(reinterpret_cast<const char*>(occluded.data()), static_cast<std::streamsize>(occluded.size()));
        }
        if (!out) throw cellrt::Error(std::string(argv[4]) + ": cannot write");
    } catch (const cellrt::Error& e) {
        std::fprintf(stderr, "cellrt_py_reference: %s\n", e.what());
        return 1;
    }
    return 0;
}
