// tinygltf (Debian's header-only tiny_gltf.h) as cellrt compiles it: without image decoding or
// writing, since cellrt reads geometry and cameras only. Every unit must see the same macros (the
// class's members depend on them), so every unit includes tinygltf through this header.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
