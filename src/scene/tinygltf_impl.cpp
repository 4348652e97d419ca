// tinygltf's implementation, compiled once into cellrt (tinygltf.hpp).
#define TINYGLTF_IMPLEMENTATION
#include "tinygltf.hpp"
