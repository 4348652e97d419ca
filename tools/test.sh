#!/usr/bin/env bash
# Second command of the README: build and run the whole test suite (CTest over GoogleTest).
# Scene tests read ../shared/scenes, or the folder named by CELLRT_SCENES.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
ctest --test-dir build --output-on-failure -j "$(nproc)"
