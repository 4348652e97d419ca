#!/usr/bin/env bash
# cellrt-mpi binaries in turn (docs/DISTRIBUTED.md, "A shared window for the pixels"): 2 ranks of
# Sponza at 1920x1080 each, the plain program on 2 threads beside them, ROUNDS rounds; rank 0's
# render seconds and each rank's time from the frame's start to its last tile, from --stats.
# Usage: ab.sh OUT_DIR ROUNDS FORMAT(pfm|png) NAME=CELLRT_MPI...
set -euo pipefail
root="$(cd "$(dirname "$0")/../../../.." && pwd)"
out="$1"; rounds="$2"; ext="$3"; shift 3
build="${CELLRT_BUILD:-$root/build}"
scene="${CELLRT_SCENES:-$root/../shared/scenes}/sponza/sponza.json"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out"
for ((r = 0; r < rounds; ++r)); do
  "$build/cellrt" render "$scene" --size 1920x1080 --threads 2 -o "$out/plain.$ext" --stats "$out/plain.$r.json" \
    --overwrite > /dev/null
  for spec in "$@"; do
    name="${spec%%=*}"
    mpirun --oversubscribe -np 2 "${spec#*=}" render "$scene" --size 1920x1080 -o "$out/$name.$ext" \
      --stats "$out/$name.$r.json" --overwrite > /dev/null
    cmp -s "$out/$name.$ext" "$out/plain.$ext" || { echo "$name: the frame differs" >&2; exit 1; }
  done
done
python3 - "$out" plain "${@%%=*}" <<'PY'
import glob, json, os, statistics, sys
out, names = sys.argv[1], sys.argv[2:]
med = statistics.median
rows = {n: [json.load(open(f)) for f in sorted(glob.glob(os.path.join(out, n + ".*.json")))] for n in names}
plain = med(d["render_seconds"] for d in rows["plain"])
print("| binary | render s, median (min-max) | ÷ plain | rank 0, rank 1 done at s, median |")
print("|---|---|--:|---|")
for n in names:
    s = [d["render_seconds"] for d in rows[n]]
    ranks = rows[n][0].get("ranks", [])
    done = ", ".join(f"{med(d['ranks'][k]['seconds'] for d in rows[n]):.4f}" for k in range(len(ranks)))
    print(f"| {n} | {med(s):.4f} ({min(s):.4f}-{max(s):.4f}) | {med(s) / plain:.3f} | {done} |")
PY
