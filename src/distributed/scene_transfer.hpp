// The scene on every rank: loaded by each from its path (the default), or loaded by rank 0 and
// broadcast (--broadcast-scene). Either way every rank checks that it holds rank 0's scene, bit for
// bit, since a frame's tiles are traced on different ranks and must see the same triangles.
#pragma once

#include <cstdint>
#include <string>

#include "cellrt/scene.hpp"
#include "distributed/session.hpp"

namespace cellrt::distributed {

// A 64-bit hash of everything a frame reads from a scene: name, triangles, camera, light and size.
std::uint64_t scene_fingerprint(const Scene& scene);

// Rank 0's `scene` to every other rank (their `scene` is replaced), in chunks MPI can count.
void broadcast_scene(const Session& session, Scene& scene);

// Throws AgreedError on every rank unless every rank's scene has rank 0's fingerprint.
void check_same_scene(const Session& session, const Scene& scene);

// The scene `spec` on every rank: loaded by each, or by rank 0 and broadcast; a rank that cannot
// load it fails the step for all (AgreedError naming it), and the scenes are compared.
Scene load_scene_on_every_rank(const Session& session, const std::string& spec, bool broadcast);

}  // namespace cellrt::distributed
