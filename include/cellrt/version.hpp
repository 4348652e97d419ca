// The library's version, as CMake's project() states it (tests/test_public_api.cpp holds them equal).
#pragma once

#define CELLRT_VERSION_MAJOR 0
#define CELLRT_VERSION_MINOR 1
#define CELLRT_VERSION_PATCH 0
#define CELLRT_VERSION_STRING "0.1.0"
// One number that grows with every release: 10000 * major + 100 * minor + patch.
#define CELLRT_VERSION (10000 * CELLRT_VERSION_MAJOR + 100 * CELLRT_VERSION_MINOR + CELLRT_VERSION_PATCH)
