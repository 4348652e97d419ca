#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/, clang-14) and runs each: first over its corpus in the
# repository, crash reproducers included, then fuzzing from it for FUZZ_SECONDS (default 60) each.
# Usage: tools/fuzz.sh [TARGET...]   (default: all; tests/fuzz/README.md lists them)
# Exits non-zero when a target crashed; the input is then under build-fuzz/fuzz-runs/TARGET/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${FUZZ_SECONDS:-60}"
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(obj ply view builtin accel cache_layout image_size)

cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
  -DCELLRT_FUZZ=ON -DCELLRT_TESTS=OFF -DCELLRT_BENCH=OFF >/dev/null
cmake --build build-fuzz --target fuzz

export UBSAN_OPTIONS="print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
failed=()
for t in "${targets[@]}"; do
  bin="build-fuzz/tests/fuzz/fuzz_$t"
  seeds="tests/fuzz/corpus/$t"
  work="build-fuzz/fuzz-runs/$t"
  mkdir -p "$work/corpus"
  rm -f "$work/replay.log" "$work/fuzz.log"
  touch "$work/stamp"  # what was saved after it is this run's
  # -timeout: an input that takes this long is a hang; -rss_limit_mb: one that needs this much
  # memory an exhaustion. Either is a failure, saved as an artifact like a crash.
  opts=(-timeout=30 -rss_limit_mb=2048 -artifact_prefix="$work/" -print_final_stats=1)
  start=$SECONDS
  # New inputs go to the first folder, the working corpus; the repository's seeds are only read.
  if "$bin" "${opts[@]}" -runs=0 "$seeds" >"$work/replay.log" 2>&1 &&
     "$bin" "${opts[@]}" -max_total_time="$seconds" "$work/corpus" "$seeds" >"$work/fuzz.log" 2>&1; then
    stats=$(grep -E '^#[0-9]+' "$work/fuzz.log" | tail -1)
    echo "fuzz_$t: ok in $((SECONDS - start)) s: $stats"
  else
    log="$work/fuzz.log"
    [ -s "$log" ] || log="$work/replay.log"
    echo "fuzz_$t: FAILED after $((SECONDS - start)) s (whole log: $log):" >&2
    grep -a -E "what\(\)|runtime error|ERROR: (Address|Leak)Sanitizer|fuzz check failed|SUMMARY|Test unit written" "$log" >&2 ||
      tail -n 20 "$log" >&2
    find "$work" -maxdepth 1 -type f -newer "$work/stamp" \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' \
      -o -name 'leak-*' -o -name 'slow-unit-*' \) >&2
    failed+=("$t")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz targets that failed: ${failed[*]}" >&2
  exit 1
fi
