// tinygltf's implementation (Debian's header-only tiny_gltf.h), compiled into cellrt without image
// decoding: cellrt reads geometry and cameras only, so images are neither decoded nor read from files.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
