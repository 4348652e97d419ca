#include "distributed/scene_transfer.hpp"

#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

namespace cellrt::distributed {
namespace {

// FNV-1a over 64-bit words (bytes for the tail): fast enough for millions of triangles.
struct Hasher {
    std::uint64_t h = 0xcbf29ce484222325ull;
    void bytes(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (; n >= 8; p += 8, n -= 8) {
            std::uint64_t w;
            std::memcpy(&w, p, 8);
            h = (h ^ w) * 0x100000001b3ull;
        }
        for (; n > 0; ++p, --n) h = (h ^ *p) * 0x100000001b3ull;
    }
    template <class T>
    void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(&v, sizeof v);
    }
};

// What a scene holds besides its name and triangles, as bytes.
struct SceneHeader {
    Camera camera;
    PointLight light;
    int width, height;
    std::uint64_t name_bytes, triangles;
};
static_assert(std::is_trivially_copyable_v<SceneHeader> && std::is_trivially_copyable_v<Triangle>);

}  // namespace

std::uint64_t scene_fingerprint(const Scene& scene) {
    Hasher h;
    h.bytes(scene.name.data(), scene.name.size());
    h.bytes(scene.triangles.data(), scene.triangles.size() * sizeof(Triangle));
    h.value(scene.camera);
    h.value(scene.light);
    h.value(scene.width);
    h.value(scene.height);
    return h.h;
}

void broadcast_scene(const Session& session, Scene& scene) {
    SceneHeader header{scene.camera, scene.light, scene.width, scene.height, scene.name.size(), scene.triangles.size()};
    session.broadcast(&header, sizeof header, "the scene's broadcast");
    if (!session.leader()) {
        scene = Scene{};
        scene.camera = header.camera;
        scene.light = header.light;
        scene.width = header.width;
        scene.height = header.height;
        scene.name.resize(header.name_bytes);
        scene.triangles.resize(header.triangles);
    }
    session.broadcast(scene.name.data(), scene.name.size(), "the scene's broadcast");
    session.broadcast(scene.triangles.data(), scene.triangles.size() * sizeof(Triangle),
                      "the scene's broadcast");
}

void check_same_scene(const Session& session, const Scene& scene) {
    std::uint64_t mine = scene_fingerprint(scene), leaders = mine;
    MPI_Request request;
    MPI_Ibcast(&leaders, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD, &request);
    session.wait(request, "the scene's fingerprint");
    std::optional<std::string> failure;
    if (mine != leaders)
        failure = "its scene '" + scene.name + "' differs from rank 0's (another file under the same path? "
                  "--broadcast-scene sends rank 0's)";
    session.agree(failure, "comparing the scenes");
}

Scene load_scene_on_every_rank(const Session& session, const std::string& spec, bool broadcast) {
    Scene scene;
    session.together([&] { if (!broadcast || session.leader()) scene = load_scene(spec); }, "loading the scene");
    if (broadcast) broadcast_scene(session, scene);
    check_same_scene(session, scene);
    return scene;
}

}  // namespace cellrt::distributed
