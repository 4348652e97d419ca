#!/usr/bin/env bash
# First command of the README: install dependencies, build (Release), render the default scene.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
./build/cellrt render -o cellrt.png --overwrite
echo "wrote $(pwd)/cellrt.png"
