#!/usr/bin/env bash
# The CUDA backend's checks on a lent GPU machine (docs/GPU.md), in two steps:
#
#   tools/device-check.sh prepare DIR   # here: build with CUDA and the benchmarks, pack the programs, their
#                                       # libraries and the shared scenes into DIR (git-ignored), compressed by
#                                       # xz where it is found (gzip elsewhere): about 20 MiB with MPI; refused
#                                       # when it and the working tree, which travels with it, pass 62 MiB
#                                       # (the device tool's limit is 64 MiB for both together)
#   tools/device-check.sh run DIR       # there, in one go (at most CELLRT_DEVICE_SECONDS, 420 s): results under $OUT
#   tools/device-check.sh run DIR STEP...  # only these steps (gpu_tests gpu_bench cache_study scaling builds
#                                       # mpi16 cache_study_async; build_curve, gpu_bench_packets,
#                                       # gpu_bih_sweep and mpi16_sweep run only when named)
#
# `run` writes $OUT/results.tar.gz and $OUT/summary.json (each step's exit status, seconds and limit, rewritten
# whole after every step, with "complete": false until the last, so that a run cut short still parses);
# the device tool returns eight files at most, so the archive holds the rest: info.log (`cellrt info
# --device cuda`), gpu_tests.json (the GPU tests, GoogleTest's JSON), gpu_bench.json and .log (the GPU
# benchmark beside Embree on all host cores, same rays), cache_study/ (the study's cache sweeps in the
# GPU's shared memory, memory mode (b), synchronous), scaling_pull_16core.json (the CPU scaling curve,
# docs/SCALING.md), builds_t1/t16 and builds_forest_t1/t16.json (docs/BUILD_SPEED.md), mpi/ and mpi_png/
# (16 ranks against one process, frames as .pfm and as .png, docs/DISTRIBUTED.md) and cache_study_async/ (the node cache's sweep with
# asynchronous access). Each step runs under a time limit of its own and the run's deadline. Without a
# CUDA device the GPU's steps are skipped, the CPU's run, and `run` ends with status 3. A step whose
# answers or frames differ from the host's exits non-zero (gpu_bench: 4; the MPI rounds: 1, also where
# a run failed), and `run` then ends with status 1, naming the failed steps in summary.json; 1 comes
# before 3, and a step cut by its own limit (status 124) counts as failed, one skipped at the run's
# deadline does not.
# With the device tool: run(command="tools/device-check.sh run .device", carry=[".device"], timeout_s=480,
# kind="nvidia-h200"): the H200 of the earlier figures, and time left in the session's 15 minutes for a
# shorter second call naming a few steps.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
usage() { echo "usage: tools/device-check.sh prepare DIR | run DIR [STEP...]" >&2; exit 2; }
[[ $# -ge 2 ]] || usage
step="$1"
dir="$2"
steps="${*:3}"

case "$step" in
prepare)
  build="${CELLRT_BUILD:-$root/build-device}"
  scenes="${CELLRT_SCENES:-$root/../shared/scenes}"
  if [[ -e "$dir" ]]; then echo "tools/device-check.sh: $dir exists; name a new folder" >&2; exit 1; fi
  command -v nvcc >/dev/null || [[ -x /usr/local/cuda/bin/nvcc ]] ||
    { echo "tools/device-check.sh: nvcc not found: the CUDA backend cannot be built here" >&2; exit 1; }
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCELLRT_CUDA=ON -DCELLRT_BENCH=ON
  targets=(cellrt_cli cellrt_tests cellrt_bench cellrt_scaling cellrt_gpu_bench)
  # cellrt-mpi where CMake found MPI (the bundle then carries mpirun too).
  if cmake --build "$build" --target help | grep -qw cellrt_mpi; then targets+=(cellrt_mpi); fi
  cmake --build "$build" -j "${CELLRT_JOBS:-2}" --target "${targets[@]}"
  stage="$(mktemp -d)" kept=false
  # Until the bundle is packed and its size checked, a failure leaves no half-made DIR behind (the
  # next prepare would refuse it as existing, or a call carry it).
  trap 'rm -rf "$stage"; $kept || rm -rf "$dir"' EXIT
  CELLRT_BUILD="$build" "$root/tools/bundle.sh" "$stage/bundle" "$build/tests/cellrt_tests" "$build/bench/cellrt_gpu_bench"
  strip "$stage/bundle/bin/"*
  mkdir -p "$stage/scenes" "$dir"
  for s in sponza sibenik bunny teapot; do
    if [[ -d "$scenes/$s" ]]; then cp -r "$scenes/$s" "$stage/scenes/"; else echo "note: scene $s not found under $scenes" >&2; fi
  done
  # xz packs the bundle to under half of gzip's size (20 MiB against 45 MB with MPI): its 64 MiB
  # dictionary (-9), in one thread (threads cut the input into blocks), finds each program's copy of
  # the statically linked library in the others; -6's 8 MiB does not (32 MiB). About three minutes
  # on two cores. The device machine unpacks it with xz or, without it, Python's tarfile.
  if command -v xz >/dev/null; then
    XZ_OPT="-9 -T1" tar -C "$stage" -cJf "$dir/device-check.tar.xz" bundle scenes
  else
    tar -C "$stage" -czf "$dir/device-check.tar.gz" bundle scenes
  fi
  # What travels to the device machine: the files git tracks, those it neither tracks nor ignores, and
  # the carried folder, 64 MiB together (a larger call is refused, costing device time).
  # (A tracked file deleted from the working tree has no size: stat's failure is not the script's.)
  tree_bytes=$(cd "$root" && { git ls-files -z --cached --others --exclude-standard; } |
    { xargs -0 -r stat -c %s -- 2>/dev/null || true; } | awk '{ s += $1 } END { print s + 0 }')
  packed_bytes=$(du -sb "$dir" | cut -f1)
  total_mib=$(( (tree_bytes + packed_bytes) / 1048576 ))
  echo "prepared $dir: $((packed_bytes / 1048576)) MiB, with the working tree $total_mib MiB of the 64 MiB that may travel"
  if (( tree_bytes + packed_bytes > 62 * 1048576 )); then
    echo "tools/device-check.sh: $dir and the working tree come to $total_mib MiB, over the 62 MiB this script allows" \
         "(64 MiB travel at most); build without MPI (-DCELLRT_MPI=OFF) or pack fewer scenes" >&2
    exit 1  # the trap removes DIR, made by this run (an existing one is refused above)
  fi
  kept=true
  ;;
run)
  out="${OUT:?run writes its results under \$OUT}"
  packed="$(cd "$dir" && pwd)/device-check.tar.xz"
  [[ -f "$packed" ]] || packed="${packed%.xz}.gz"
  dir="$(mktemp -d)"
  trap 'rm -rf "$dir"' EXIT
  if [[ "$packed" == *.gz ]] || command -v xz >/dev/null; then
    tar -C "$dir" -xaf "$packed"
  else
    python3 -c 'import sys, tarfile
kept = {"filter": "tar"} if hasattr(tarfile, "tar_filter") else {}  # links and modes as packed
tarfile.open(sys.argv[1]).extractall(sys.argv[2], **kept)' "$packed" "$dir"
  fi
  run="$dir/bundle/run"
  res="$dir/results"
  mkdir -p "$res/mpi" "$res/mpi_sweep" "$dir/frames"
  lscpu > "$res/lscpu.txt" 2>&1 || true
  export CELLRT_SCENES="$dir/scenes" CELLRT_CLI="$dir/bundle/cellrt-cli" CELLRT_TEST_CACHE="$dir/reference_cache"
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  # The tests start the program by one path: a wrapper with the bundle's libraries.
  printf '#!/usr/bin/env bash\nexec "%s" cellrt "$@"\n' "$run" > "$CELLRT_CLI"
  chmod +x "$CELLRT_CLI"
  # The device tool returns at most eight files: every result goes into one archive, packed again
  # after each step (and renamed into place), so that a call cut short still returns what was done.
  # Each step stops at its own limit or at the run's deadline, whichever comes first.
  deadline=$((SECONDS + ${CELLRT_DEVICE_SECONDS:-420}))
  summary="$res/summary.json" entries="$dir/summary.entries" gpu=null failed=()
  : > "$entries"
  pack() {  # the results so far into $OUT, renamed into place
    tar -C "$dir" -czf "$out/.results.tar.gz" results && mv "$out/.results.tar.gz" "$out/results.tar.gz"
  }
  note() {  # NAME JSON [COMPLETE]: one step's entry; the summary is written whole again, valid JSON at every step
    echo "  \"$1\": $2" >> "$entries"
    { echo "{"; sed 's/$/,/' "$entries"; echo "  \"device\": $gpu, \"complete\": ${3:-false}"; echo "}"; } > "$summary"
    cp "$summary" "$out/summary.json"
  }
  timed() {  # NAME LIMIT_S COMMAND...: runs it under its limit, logs to NAME.log, notes status and time
    local name="$1" limit="$2"; shift 2
    local left=$((deadline - SECONDS)) start=$SECONDS status=0
    if ((left < limit)); then limit=$left; fi
    if ((limit < 5)); then
      note "$name" "{\"status\": \"skipped: the run's deadline\"}"
      echo "$name: skipped (the run's deadline)"
      return
    fi
    timeout "$limit" "$@" > "$res/$name.log" 2>&1 || status=$?
    note "$name" "{\"status\": $status, \"seconds\": $((SECONDS - start)), \"limit\": $limit}"
    echo "$name: status $status, $((SECONDS - start)) s (limit $limit s)"
    # info's status says whether there is a device (3: none), not whether it failed.
    if ((status != 0)) && [[ "$name" != info ]]; then failed+=("\"$name\""); fi
    pack
  }
  timed info 20 "$run" cellrt info --device cuda
  # Without a GPU (a driver that fails, a machine lent without one) the CPU's steps still run: the
  # 16-core scaling, build and MPI figures are wanted whatever the GPU does. The run then ends with
  # status 3.
  gpu=true
  if ! grep -q '^cuda ' "$res/info.log"; then
    echo "no CUDA device: $(cat "$res/info.log"); the GPU's steps are skipped"
    gpu=false
  fi
  named() { [[ " $steps " == *" $1 "* ]]; }     # steps that run only when named
  wanted() { [[ -z "$steps" ]] || named "$1"; }  # steps of the default run
  on_gpu() {  # NAME: a GPU step, skipped (and noted) without a device
    $gpu && return 0
    note "$1" "{\"status\": \"skipped: no CUDA device\"}"
    return 1
  }
  wanted gpu_tests && on_gpu gpu_tests && timed gpu_tests 120 "$run" cellrt_tests --gtest_filter='*Cuda*' --gtest_output="json:$res/gpu_tests.json"
  wanted gpu_bench && on_gpu gpu_bench && timed gpu_bench 200 "$run" cellrt_gpu_bench --scenes-dir "$CELLRT_SCENES" \
    --scenes sponza sibenik bunny builtin:city --size 1920x1080 --rays frame ao diffuse --repeats 3 --json "$res/gpu_bench.json"
  wanted cache_study && on_gpu cache_study && timed cache_study 50 "$run" cellrt cache-study "$CELLRT_SCENES/sponza/sponza.json" --device cuda \
    --size 1920x1080 --sample 4 --structures kd bih --traversals branched --access sync -o "$res/cache_study"
  wanted scaling && timed scaling 60 "$run" cellrt_scaling --scenes-dir "$CELLRT_SCENES" --dispatch pull --packets 16 \
    --repeats 3 --workers 1 2 4 8 16 --configs embree:single kd+auto bih+auto --json "$res/scaling_pull_16core.json"
  # Embree's packets as the yardstick (gpu_bench's default is rtcIntersect1), against the fastest
  # configuration of each tree in memory mode (a) (not by default).
  if named gpu_bench_packets && on_gpu gpu_bench_packets; then
    for w in 8 16; do
      timed "gpu_bench_packet$w" 80 "$run" cellrt_gpu_bench --scenes-dir "$CELLRT_SCENES" \
        --scenes sponza sibenik bunny builtin:city --size 1920x1080 --rays frame ao diffuse --repeats 3 \
        --configs kd:branched kd:rec bih:branched@split=sah --cpu-config "embree:packet$w" \
        --json "$res/gpu_bench_packet$w.json"
    done
  fi
  # The SAH BIH's build costs on the GPU, Sponza (docs/GPU.md; not by default): the node cost against the
  # triangle test's (20) and the empty-space cut, with the kd-tree for reference.
  if named gpu_bih_sweep && on_gpu gpu_bih_sweep; then
    configs=(kd:branched)
    for c in 15 30 60 120; do
      for e in 0.23 1; do configs+=("bih:branched@split=sah,traversal_cost=$c,empty_cut=$e"); done
    done
    configs+=("bih:branchless@split=sah,traversal_cost=60" "bih:branched@split=sah,traversal_cost=60,sah_max_leaf=64")
    timed gpu_bih_sweep 120 "$run" cellrt_gpu_bench --scenes-dir "$CELLRT_SCENES" --scenes sponza sibenik \
      --size 1920x1080 --rays frame diffuse --repeats 3 --configs "${configs[@]}" --json "$res/gpu_bih_sweep.json"
  fi
  # Builds on 1 and 16 threads (docs/BUILD_SPEED.md): the shared scenes, then the 1M-triangle forest.
  if wanted builds; then
    for t in 1 16; do
      timed "builds_t$t" 40 "$run" cellrt_bench --scenes-dir "$CELLRT_SCENES" --scenes sponza sibenik bunny teapot \
        --size 16x16 --repeats 1 --builds 2 --threads "$t" --configs embree kd bih@split=sah --json "$res/builds_t$t.json"
    done
    for t in 1 16; do
      timed "builds_forest_t$t" 40 "$run" cellrt_bench --scenes 'builtin:forest?tris=1000000' --size 16x16 --repeats 1 \
        --builds 1 --threads "$t" --configs embree kd bih@split=sah --json "$res/builds_forest_t$t.json"
    done
  fi
  # The build's curve over 1 to 16 threads, five builds each (not by default).
  if named build_curve; then
    for t in 1 2 4 8 16; do
      timed "build_curve_t$t" 30 "$run" cellrt_bench --scenes-dir "$CELLRT_SCENES" --scenes sponza bunny --size 16x16 \
        --repeats 1 --builds 5 --threads "$t" --configs embree kd bih@split=sah --json "$res/build_curve_t$t.json"
    done
  fi
  # Runs of `cellrt render` and `cellrt-mpi render` of Sponza at 1080p (docs/DISTRIBUTED.md), five rounds
  # with the configurations in turn, each frame compared byte for byte with the first configuration's;
  # each run's time is rank 0's frame_seconds in its --stats file (the frame from its memory to its
  # last pixel, the same span in both programs), without start-up, loading and building. Frames
  # are written as .pfm (float pixels), or as .png with FRAME_EXT=png (cellrt-mpi's ranks then send
  # 8-bit pixels). mpi_rounds INTO NAME=PROGRAM ARGS...
  # Status 1 when a run failed or a frame differed, after every round was run. A NAME ending in '?'
  # is a run the machine may refuse (a transport asked for by name): its failure is logged, not
  # counted; a frame it made that differs still is.
  mpi_rounds() {
    local into="$1" first="${2%%=*}" ext="${FRAME_EXT:-pfm}" spec name args r failed=0 optional status
    shift
    mkdir -p "$into"
    for r in 1 2 3 4 5; do
      for spec in "$@"; do
        name="${spec%%=*}" optional=false status=0
        if [[ "$name" == *"?" ]]; then name="${name%"?"}" optional=true; fi
        read -ra args <<<"${spec#*=}"
        rm -f "$frames/$name.$ext"
        "$run" "${args[@]}" --size 1920x1080 -o "$frames/$name.$ext" --stats "$into/$name.$r.json" --overwrite \
          > /dev/null || status=$?
        if ((status != 0)); then
          echo "$name: status $status"
          $optional || failed=1
          continue
        fi
        cmp "$frames/$name.$ext" "$frames/$first.$ext" || { echo "$name: the frame differs"; failed=1; }
      done
    done
    return "$failed"
  }
  frames="$dir/frames" sponza="$CELLRT_SCENES/sponza/sponza.json"
  export -f mpi_rounds
  export run frames
  plain="cellrt render $sponza"
  mpi="mpirun --oversubscribe --bind-to none"
  # 16 ranks against one process: the pixels through rank 0's shared window (the default) and as
  # messages, the way before it. mpi16_messages_cma asks Open MPI for its single-copy transport by
  # name: it says so where the machine refuses it (yama's ptrace_scope, or a container without ptrace).
  if [[ -x "$dir/bundle/bin/cellrt-mpi" ]] && wanted mpi16; then
    cat /proc/sys/kernel/yama/ptrace_scope > "$res/mpi/ptrace_scope.txt" 2>&1 || true
    timed mpi16 90 bash -c 'mpi_rounds "$@"' _ "$res/mpi" "plain_t16=$plain --threads 16" \
      "plain_t1=$plain --threads 1" "mpi16=$mpi -np 16 cellrt-mpi render $sponza --threads 1" \
      "mpi16_tile64=$mpi -np 16 cellrt-mpi render $sponza --threads 1 --tile 64" \
      "mpi16_messages=$mpi -np 16 cellrt-mpi render $sponza --threads 1 --gather messages" \
      "mpi16_messages_cma?=$mpi --mca btl_vader_single_copy_mechanism cma -np 16 cellrt-mpi render $sponza --threads 1 --gather messages"
    # The same frame written as PNG: the ranks make 8-bit pixels, a quarter of the floats' bytes.
    export FRAME_EXT=png
    timed mpi16_png 60 bash -c 'mpi_rounds "$@"' _ "$res/mpi_png" "plain_t16=$plain --threads 16" \
      "plain_t1=$plain --threads 1" "mpi16=$mpi -np 16 cellrt-mpi render $sponza --threads 1" \
      "mpi16_messages=$mpi -np 16 cellrt-mpi render $sponza --threads 1 --gather messages"
    unset FRAME_EXT
  fi
  # What holds 16 ranks back (not by default): tiles held ahead, tile edge, binding, ranks, transport.
  if [[ -x "$dir/bundle/bin/cellrt-mpi" ]] && named mpi16_sweep; then
    timed mpi16_sweep 100 bash -c 'mpi_rounds "$@"' _ "$res/mpi_sweep" "plain_t16=$plain --threads 16" \
      "mpi16=$mpi -np 16 cellrt-mpi render $sponza --threads 1" \
      "mpi16_ahead6=$mpi -np 16 cellrt-mpi render $sponza --threads 1 --ahead 6" \
      "mpi16_ahead12=$mpi -np 16 cellrt-mpi render $sponza --threads 1 --ahead 12" \
      "mpi16_tile256=$mpi -np 16 cellrt-mpi render $sponza --threads 1 --tile 256" \
      "mpi16_core=mpirun --oversubscribe --bind-to core -np 16 cellrt-mpi render $sponza --threads 1" \
      "mpi15=$mpi -np 15 cellrt-mpi render $sponza --threads 1" \
      "mpi16_messages_cma_ahead6?=$mpi --mca btl_vader_single_copy_mechanism cma -np 16 cellrt-mpi render $sponza --threads 1 --ahead 6 --gather messages" \
      "mpi4x4=$mpi -np 4 cellrt-mpi render $sponza --threads 4"
  fi
  # Last, as the step a short call may cut: asynchronous access, whose touches reach the node cache only.
  wanted cache_study_async && on_gpu cache_study_async && timed cache_study_async 30 "$run" cellrt cache-study "$CELLRT_SCENES/sponza/sponza.json" \
    --device cuda --size 1920x1080 --sample 4 --structures kd bih --traversals branched --access async --sweeps node \
    -o "$res/cache_study_async"
  note run "{\"seconds\": $SECONDS, \"failed\": [$(IFS=,; echo "${failed[*]}")]}" true
  pack
  if ((${#failed[@]} > 0)); then echo "failed: ${failed[*]}"; exit 1; fi
  $gpu || exit 3
  ;;
*) usage ;;
esac
