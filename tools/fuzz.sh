#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/, clang-14) and runs each: first over its corpus in the
# repository, crash reproducers included, then fuzzing from it for FUZZ_SECONDS (default 60) each,
# FUZZ_JOBS targets at a time (default: one per core; each libFuzzer process uses one).
# Usage: tools/fuzz.sh [TARGET...]   (default: all; tests/fuzz/README.md lists them)
# Exits non-zero when a target failed, naming the input: the repository's file where one of the
# corpus failed, else the input saved under build-fuzz/fuzz-runs/TARGET/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${FUZZ_SECONDS:-60}"
jobs="${FUZZ_JOBS:-$(nproc)}"
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(obj ply view builtin accel cache_layout image_size gltf)

cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
  -DCELLRT_FUZZ=ON -DCELLRT_TESTS=OFF -DCELLRT_BENCH=OFF -DCELLRT_CUDA=OFF >/dev/null
cmake --build build-fuzz --target fuzz

# Only the kernels may use instructions beyond x86-64's baseline, each set its own (clang's target
# attribute in src/accel/kernels_<isa>.cpp), so that the targets run on any x86-64 processor:
# functions elsewhere holding AVX, AVX-512 or SSE4 instructions fail the run (libFuzzer's own hooks
# use popcnt). One target suffices, all linking the same library.
beyond=$(objdump -d --no-show-raw-insn -C build-fuzz/tests/fuzz/fuzz_accel | awk '
  /^[0-9a-f]+ <.*>:$/ { fn = $0; next }
  fn !~ /cellrt::detail::isa_(sse|avx2|avx512)::|<__sanitizer_cov_/ &&
    ($0 ~ /%[yz]mm|%k[0-7]|\tv[a-z]/ ||
     $0 ~ /\t(ptest|pblendvb|blendvp[sd]|roundp[sd]|rounds[sd]|pmulld|pmins[bd]|pmaxs[bd]|insertps|extractps|pextr[bdq]|pinsr[bdq]|dpp[sd]|pcmpeqq|pcmpgtq|crc32|popcnt|pshufb|lzcnt|tzcnt)( |$)/) { print fn; }' | sort -u)
if [ -n "$beyond" ]; then
  echo "tools/fuzz.sh: functions outside the kernels use instructions beyond x86-64's baseline:" >&2
  echo "$beyond" | head -n 20 >&2
  exit 1
fi

export UBSAN_OPTIONS="print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"

# One target: replay, then fuzz. Its summary goes to $work/result, its status is the run's.
run_target() {
  local t="$1" bin="build-fuzz/tests/fuzz/fuzz_$1" seeds="tests/fuzz/corpus/$1" work="build-fuzz/fuzz-runs/$1"
  mkdir -p "$work/corpus"
  rm -f "$work/replay.log" "$work/fuzz.log" "$work/result"
  touch "$work/stamp"  # what was saved after it is this run's
  # -timeout: an input that takes this long is a hang; -rss_limit_mb: one that needs this much
  # memory an exhaustion. Either is a failure, saved as an artifact like a crash.
  local opts=(-timeout=30 -rss_limit_mb=2048 -artifact_prefix="$work/" -print_final_stats=1)
  local start=$SECONDS
  # New inputs go to the first folder, the working corpus; the repository's seeds are only read.
  if "$bin" "${opts[@]}" -runs=0 "$seeds" >"$work/replay.log" 2>&1 &&
     "$bin" "${opts[@]}" -max_total_time="$seconds" "$work/corpus" "$seeds" >"$work/fuzz.log" 2>&1; then
    echo "fuzz_$t: ok in $((SECONDS - start)) s: $(grep -E '^#[0-9]+' "$work/fuzz.log" | tail -1)" >"$work/result"
    return 0
  fi
  local log="$work/fuzz.log" saved
  [ -s "$log" ] || log="$work/replay.log"
  {
    echo "fuzz_$t: FAILED after $((SECONDS - start)) s (whole log: $log):"
    grep -a -E "what\(\)|runtime error|ERROR: (Address|Leak)Sanitizer|fuzz check failed|SUMMARY" "$log" ||
      tail -n 20 "$log"
    # libFuzzer names a saved input by its SHA-1: a file of the corpus with that hash is the reproducer.
    for saved in $(find "$work" -maxdepth 1 -type f -newer "$work/stamp" \( -name 'crash-*' -o -name 'timeout-*' \
                     -o -name 'oom-*' -o -name 'leak-*' -o -name 'slow-unit-*' \)); do
      local hash=${saved##*-} from
      from=$(find "$seeds" -type f -exec sha1sum {} + | awk -v h="$hash" '$1 == h { print $2; exit }')
      echo "reproducer: $saved${from:+, the committed $from}"
    done
  } >"$work/result"
  return 1
}

# Each target in the background, at most $jobs at once; its status is kept in $work/status.
for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  (rc=0; run_target "$t" || rc=$?; echo "$rc" >"build-fuzz/fuzz-runs/$t/status") &
done
wait
failed=()
for t in "${targets[@]}"; do
  if [ "$(cat "build-fuzz/fuzz-runs/$t/status")" = 0 ]; then
    cat "build-fuzz/fuzz-runs/$t/result"
  else
    cat "build-fuzz/fuzz-runs/$t/result" >&2
    failed+=("$t")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz targets that failed: ${failed[*]}" >&2
  exit 1
fi
