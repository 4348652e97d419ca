#!/usr/bin/env bash
# cellrt-mpi against one process (docs/DISTRIBUTED.md). Each configuration renders the frame, and a
# 16 x 16 frame that costs the same loading, building and start-up; runs interleaved (one of each in
# turn, REPS rounds). Reported, medians: the frame time (rank 0's wall time for the frame), the whole
# command's wall time less the 16 x 16 run's, and the frame's CPU time, the CPU seconds of the whole
# command (all ranks and mpirun, from getrusage) less those of the 16 x 16 run: on a machine shared
# with other work the wall time follows the share of the cores a run gets, the CPU time what the run
# costs. Usage:
#   bench/mpi_efficiency.sh SCENE [REPS] [SIZE]      (build/cellrt and build/cellrt-mpi must exist)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELLRT_BUILD:-$root/build}"
scene="$1"; reps="${2:-7}"; size="${3:-1920x1080}"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 LC_ALL=C  # EPOCHREALTIME's decimal point
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
declare -A cmd=(
  [plain_2threads]="$build/cellrt render $scene --threads 2"
  [mpi1_2threads]="mpirun -np 1 --bind-to none $build/cellrt-mpi render $scene --threads 2"
  [mpi2]="mpirun -np 2 $build/cellrt-mpi render $scene"
  [mpi2_tile64]="mpirun -np 2 $build/cellrt-mpi render $scene --tile 64"
)
names=(plain_2threads mpi1_2threads mpi2 mpi2_tile64)
for ((r = 0; r < reps; ++r)); do
  for n in "${names[@]}"; do
    for s in "$size" 16x16; do
      start=$EPOCHREALTIME
      /usr/bin/time -f "%U %S" -o "$work/cpu.txt" ${cmd[$n]} --size "$s" -o "$work/$n.$s.pfm" \
        --stats "$work/$n.$s.$r.json" --overwrite > /dev/null
      echo "$n $s $(cat "$work/cpu.txt") $start $EPOCHREALTIME" >> "$work/time.txt"
    done
    cmp -s "$work/$n.$size.pfm" "$work/plain_2threads.$size.pfm" || { echo "$n: the frame differs" >&2; exit 1; }
  done
done
python3 - "$work" "$size" "${names[@]}" <<'PY'
import json, statistics, sys, glob, os
work, size, names = sys.argv[1], sys.argv[2], sys.argv[3:]
cpu, wall = {}, {}
for line in open(os.path.join(work, "time.txt")):
    n, s, u, k, start, end = line.split()
    cpu.setdefault((n, s), []).append(float(u) + float(k))
    wall.setdefault((n, s), []).append(float(end) - float(start))
med = statistics.median
# frame s: the frame from its memory to its last pixel (--stats frame_seconds), alike for both
# programs (their render_seconds are not: cellrt's is the tracing alone). frame wall s: the whole
# command's elapsed time less the 16 x 16 run's (bash's EPOCHREALTIME, microseconds), the frame's
# file written included. frame CPU s: at /usr/bin/time's 10 ms resolution.
print(f"{'configuration':16} {'frame s':>9} {'min':>6} {'max':>6} {'ratio':>6} {'frame wall s':>13} {'ratio':>6} "
      f"{'frame CPU s':>12} {'ratio':>6}")
base = None
for n in names:
    runs = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(work, f"{n}.{size}.*.json")))]
    t = [j["frame_seconds"] for j in runs]
    frame_wall = med(wall[(n, size)]) - med(wall[(n, "16x16")])
    frame_cpu = med(cpu[(n, size)]) - med(cpu[(n, "16x16")])
    base = base or (med(t), frame_wall, frame_cpu)
    # A frame too small for /usr/bin/time's 10 ms shows no CPU time: its ratio is not a number.
    cpu_ratio = f"{frame_cpu / base[2]:6.3f}" if base[2] > 0 else "     –"
    print(f"{n:16} {med(t):9.4f} {min(t):6.3f} {max(t):6.3f} {med(t) / base[0]:6.3f} {frame_wall:13.4f} "
          f"{frame_wall / base[1]:6.3f} {frame_cpu:12.3f} {cpu_ratio}")
    if "ranks" in runs[-1]:
        for k in runs[-1]["ranks"]:
            print(f"    rank {k['rank']}: {k['threads']} threads, {k['tiles']} tiles, busy {k['busy_seconds']:.3f} s of "
                  f"{k['seconds']:.3f} s, CPU {k['cpu_seconds']:.3f} s" +
                  (f" (master {k['master_cpu_seconds']:.3f} s)" if "master_cpu_seconds" in k else ""))
PY
