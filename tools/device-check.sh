#!/usr/bin/env bash
# The CUDA backend's checks on a lent GPU machine (docs/GPU.md), in two steps:
#
#   tools/device-check.sh prepare DIR   # here: build with CUDA and the benchmarks, pack the programs, their
#                                       # libraries and the shared scenes into DIR (git-ignored), compressed:
#                                       # about 26 MB (43 MB from a build with MPI) against the 64 MiB carry limit
#   tools/device-check.sh run DIR       # there, in one go (about 8 minutes at most): results under $OUT
#
# `run` writes $OUT/info.txt (`cellrt info --device cuda`), $OUT/gpu_tests.json (the GPU tests, GoogleTest's
# JSON), $OUT/gpu_bench.json and .md (the GPU benchmark beside Embree on all host cores, same rays),
# $OUT/cache_study/ (the study's cache sweeps in the GPU's shared memory, memory mode (b), synchronous),
# $OUT/scaling_pull_16core.json (the CPU scaling curve, docs/SCALING.md) and $OUT/cache_study_async/ (the
# node cache's sweep with asynchronous access), each step under a time limit
# of its own, and $OUT/summary.json with each step's exit status and seconds.
# With the device tool: run(command="tools/device-check.sh run .device", carry=[".device"], timeout_s=560).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
usage() { echo "usage: tools/device-check.sh prepare DIR | run DIR" >&2; exit 2; }
[[ $# -eq 2 ]] || usage
step="$1"
dir="$2"

case "$step" in
prepare)
  build="${CELLRT_BUILD:-$root/build-device}"
  scenes="${CELLRT_SCENES:-$root/../shared/scenes}"
  if [[ -e "$dir" ]]; then echo "tools/device-check.sh: $dir exists; name a new folder" >&2; exit 1; fi
  command -v nvcc >/dev/null || [[ -x /usr/local/cuda/bin/nvcc ]] ||
    { echo "tools/device-check.sh: nvcc not found: the CUDA backend cannot be built here" >&2; exit 1; }
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCELLRT_CUDA=ON -DCELLRT_BENCH=ON
  cmake --build "$build" -j "${CELLRT_JOBS:-2}" --target cellrt_cli cellrt_tests cellrt_bench cellrt_scaling cellrt_gpu_bench
  stage="$(mktemp -d)"
  trap 'rm -rf "$stage"' EXIT
  CELLRT_BUILD="$build" "$root/tools/bundle.sh" "$stage/bundle" "$build/tests/cellrt_tests" "$build/bench/cellrt_gpu_bench"
  strip "$stage/bundle/bin/"*
  mkdir -p "$stage/scenes" "$dir"
  for s in sponza sibenik bunny teapot; do
    if [[ -d "$scenes/$s" ]]; then cp -r "$scenes/$s" "$stage/scenes/"; else echo "note: scene $s not found under $scenes" >&2; fi
  done
  tar -C "$stage" -czf "$dir/device-check.tar.gz" bundle scenes
  echo "prepared $dir ($(du -sh "$dir" | cut -f1); the carry limit is 64 MiB)"
  ;;
run)
  out="${OUT:?run writes its results under \$OUT}"
  packed="$(cd "$dir" && pwd)/device-check.tar.gz"
  dir="$(mktemp -d)"
  trap 'rm -rf "$dir"' EXIT
  tar -C "$dir" -xzf "$packed"
  run="$dir/bundle/run"
  export CELLRT_SCENES="$dir/scenes" CELLRT_CLI="$dir/bundle/cellrt-cli" CELLRT_TEST_CACHE="$out/.reference_cache"
  # The tests start the program by one path: a wrapper with the bundle's libraries.
  printf '#!/usr/bin/env bash\nexec "%s" cellrt "$@"\n' "$run" > "$CELLRT_CLI"
  chmod +x "$CELLRT_CLI"
  summary="$out/summary.json"
  echo "{" > "$summary"
  timed() {  # NAME LIMIT_S COMMAND...: runs it under its limit, logs to $OUT/NAME.log, notes status and time
    local name="$1" limit="$2"; shift 2
    local start=$SECONDS status=0
    timeout "$limit" "$@" > "$out/$name.log" 2>&1 || status=$?
    echo "  \"$name\": {\"status\": $status, \"seconds\": $((SECONDS - start))}," >> "$summary"
    echo "$name: status $status, $((SECONDS - start)) s"
  }
  timed info 30 "$run" cellrt info --device cuda
  cp "$out/info.log" "$out/info.txt"
  if ! grep -q '^cuda ' "$out/info.txt"; then
    echo "no CUDA device: $(cat "$out/info.txt")"
    echo "  \"device\": false }" >> "$summary"
    exit 3
  fi
  timed gpu_tests 150 "$run" cellrt_tests --gtest_filter='*Cuda*' --gtest_output="json:$out/gpu_tests.json"
  timed gpu_bench 240 "$run" cellrt_gpu_bench --scenes-dir "$CELLRT_SCENES" --scenes sponza sibenik bunny builtin:city \
    --size 1920x1080 --rays frame ao diffuse --repeats 3 --json "$out/gpu_bench.json"
  cp "$out/gpu_bench.log" "$out/gpu_bench.md"
  timed cache_study 75 "$run" cellrt cache-study "$CELLRT_SCENES/sponza/sponza.json" --device cuda --size 1920x1080 \
    --sample 4 --structures kd bih --traversals branched --access sync -o "$out/cache_study"
  timed scaling 100 "$run" cellrt_scaling --scenes-dir "$CELLRT_SCENES" --dispatch pull --packets 16 --repeats 3 \
    --workers 1 2 4 8 12 16 --configs embree:single kd+auto bih+auto --json "$out/scaling_pull_16core.json"
  # Last, as the step a short call may cut: asynchronous access, whose touches reach the node cache only.
  timed cache_study_async 45 "$run" cellrt cache-study "$CELLRT_SCENES/sponza/sponza.json" --device cuda \
    --size 1920x1080 --sample 4 --structures kd bih --traversals branched --access async --sweeps node \
    -o "$out/cache_study_async"
  rm -rf "$CELLRT_TEST_CACHE"
  echo "  \"device\": true }" >> "$summary"
  ;;
*) usage ;;
esac
