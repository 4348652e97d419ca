#!/usr/bin/env bash
# Two ranks against one process of two threads, on the span both programs' frames share
# (docs/DISTRIBUTED.md, "Two ranks, frame for frame"): Sponza at 1920x1080, ROUNDS rounds, the plain
# program and cellrt-mpi in turn (the order swapped every other round), every frame compared byte for
# byte with the plain program's. From --stats: render_seconds (the plain program: the tracing alone;
# cellrt-mpi: its whole frame) and frame_seconds (both: the frame from its memory to its last pixel).
# Usage: run.sh OUT_DIR ROUNDS FORMAT(pfm|png)
set -euo pipefail
root="$(cd "$(dirname "$0")/../../../.." && pwd)"
out="$1"; rounds="$2"; ext="$3"
build="${CELLRT_BUILD:-$root/build}"
scene="${CELLRT_SCENES:-$root/../shared/scenes}/sponza/sponza.json"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out"
plain() { "$build/cellrt" render "$scene" --size 1920x1080 --threads 2 -o "$out/plain.$ext" --stats "$out/plain.$1.json" \
  --overwrite > /dev/null; }
mpi() { mpirun --oversubscribe -np 2 "$build/cellrt-mpi" render "$scene" --size 1920x1080 -o "$out/mpi2.$ext" \
  --stats "$out/mpi2.$1.json" --overwrite > /dev/null; }
for ((r = 0; r < rounds; ++r)); do
  if ((r % 2)); then mpi "$r"; plain "$r"; else plain "$r"; mpi "$r"; fi
  cmp -s "$out/mpi2.$ext" "$out/plain.$ext" || { echo "the frames differ" >&2; exit 1; }
done
python3 - "$out" "$ext" <<'PY'
import glob, json, os, statistics, sys
out, ext = sys.argv[1], sys.argv[2]
med = statistics.median
runs = {n: [json.load(open(f)) for f in sorted(glob.glob(os.path.join(out, n + ".*.json")))] for n in ("plain", "mpi2")}
print(f"| pixels ({ext}) | figure | plain, 2 threads s | 2 ranks s | ÷ plain | per round ÷, median (min-max) | rounds |")
print("|---|---|--:|--:|--:|---|--:|")
for key in ("render_seconds", "frame_seconds"):
    p = [d[key] for d in runs["plain"]]
    m = [d[key] for d in runs["mpi2"]]
    pair = [b / a for a, b in zip(p, m)]
    print(f"| {ext} | {key} | {med(p):.4f} | {med(m):.4f} | {med(m) / med(p):.3f} | "
          f"{med(pair):.3f} ({min(pair):.3f}-{max(pair):.3f}) | {len(p)} |")
PY
