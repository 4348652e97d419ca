#!/usr/bin/env bash
# Second command of the README: build and run the whole test suite (CTest over GoogleTest) in a
# Release build, then again under sanitizers (docs/RELIABILITY.md): all of it under AddressSanitizer and
# UndefinedBehaviorSanitizer, the tests that start threads under ThreadSanitizer, and last the libFuzzer
# targets, each over its corpus and then for FUZZ_SECONDS (tools/fuzz.sh). A stage's name (release,
# asan, tsan or fuzz) runs that stage alone. Scene tests read ../shared/scenes, or the folder named
# by CELLRT_SCENES.
set -euo pipefail
cd "$(dirname "$0")/.."
stages=("$@")
[ "${#stages[@]}" -gt 0 ] || stages=(release asan tsan fuzz)
jobs="$(nproc)"

# Sanitized builds: -O1, which the sanitizers' documentation advises for a bearable speed, and -g1,
# line tables only: file and line in the reports, for two thirds of -g's compile time (CI's budget).
# They build the programs the suite runs, and not the benchmarks (the Release stage compiles those and
# runs their two end-to-end tests, Bench.ScalingStudyEndToEnd and Tools.BundleRunsItsProgramsWithItsOwnLibraries:
# a minute and a half of the ASan stage's build for code of the library that the rest of its suite
# meets): the whole-suite run needs the test programs and cellrt; ThreadSanitizer's share needs only
# the test program (tests/CMakeLists.txt). MPI, the
# CUDA backend (the device code has no sanitizer; the host tests of that same code, DeviceCode.*,
# still run) and the Python module are left out of them (CMakeLists.txt says why).
sanitized_stage() {  # build folder, sanitizers, targets to build (space-separated), further CMake arguments
  local dir="$1" sanitizers="$2" targets="$3"
  shift 3
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DCELLRT_SANITIZE="$sanitizers" -DCELLRT_CUDA=OFF "$@"
  # shellcheck disable=SC2086 # the targets are words
  cmake --build "$dir" --target $targets
  ctest --test-dir "$dir" --output-on-failure -j "$jobs"
  # CTest lists the skipped tests by name; their reasons are in its log.
  echo "Skipped under -fsanitize=$sanitizers, and why:"
  grep -h -B2 "built with -fsanitize" "$dir/Testing/Temporary/LastTest.log" | grep -v '^--$' || echo "(none)"
}

# Reports carry whole stacks; the Release build's cached brute-force answers serve the sanitized runs,
# which recompute a sample of each (tests/ray_suite.hpp) instead of minutes of brute force per scene.
export UBSAN_OPTIONS="print_stacktrace=1"
export TSAN_OPTIONS="second_deadlock_stack=1"
export CELLRT_TEST_CACHE="$PWD/build/tests/reference_cache"

times=()
for stage in "${stages[@]}"; do
  echo "== tools/test.sh: $stage"
  start=$SECONDS
  case "$stage" in
    release)
      cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
      cmake --build build
      ctest --test-dir build --output-on-failure -j "$jobs"
      ;;
    asan)
      sanitized_stage build-asan address,undefined "cellrt_tests cellrt_capi_test cellrt_cli cellrt_c" -DCELLRT_BENCH=OFF
      ;;
    tsan)
      echo "ThreadSanitizer runs the tests that start threads, TBB on one thread (docs/RELIABILITY.md)"
      sanitized_stage build-tsan thread cellrt_tests -DCELLRT_BENCH=OFF
      ;;
    fuzz)
      # CI's budget: two targets at a time (one core each), 30 s of fuzzing each after the replay.
      if command -v clang++-14 >/dev/null; then
        FUZZ_SECONDS="${FUZZ_SECONDS:-30}" tools/fuzz.sh
      else
        echo "SKIPPED: the fuzz stage needs clang++-14 (packages.txt; tools/install-deps.sh installs it)"
      fi
      ;;
    *)
      echo "tools/test.sh: unknown stage '$stage' (release, asan, tsan, fuzz)" >&2
      exit 2
      ;;
  esac
  times+=("$stage $((SECONDS - start)) s")
done
echo "== tools/test.sh: passed; wall time per stage: $(IFS=,; echo "${times[*]}" | sed 's/,/, /g')"
