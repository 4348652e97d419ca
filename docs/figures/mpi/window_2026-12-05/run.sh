#!/usr/bin/env bash
# The shared window against messages for the tiles' pixels (docs/DISTRIBUTED.md, "A shared window for
# the pixels"): 2 ranks of Sponza at 1920x1080, Open MPI's defaults and without its single-copy
# transport (the 16-rank symptom on 2 cores), interleaved, ROUNDS rounds; rank 0's render seconds and
# rank 1's busy share of the frame, from --stats; the plain program on 2 threads beside them (its
# render seconds). Usage: run.sh OUT_DIR [ROUNDS] [FORMAT: pfm or png]
set -euo pipefail
root="$(cd "$(dirname "$0")/../../../.." && pwd)"
out="$1"; rounds="${2:-5}"; ext="${3:-pfm}"
build="${CELLRT_BUILD:-$root/build}"
scene="${CELLRT_SCENES:-$root/../shared/scenes}/sponza/sponza.json"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out"
"$build/cellrt" render "$scene" --size 1920x1080 --threads 2 -o "$out/plain.$ext" --overwrite > /dev/null
for ((r = 0; r < rounds; ++r)); do
  "$build/cellrt" render "$scene" --size 1920x1080 --threads 2 -o "$out/plain.$ext" --stats "$out/plain.$r.json" \
    --overwrite > /dev/null
  for transport in default nocopy; do
    env=(); [[ $transport == nocopy ]] && env=(-x OMPI_MCA_btl_vader_single_copy_mechanism=none)
    for gather in window messages; do
      name="${gather}_${transport}"
      mpirun --oversubscribe "${env[@]}" -np 2 "$build/cellrt-mpi" render "$scene" --size 1920x1080 \
        --gather "$gather" -o "$out/$name.$ext" --stats "$out/$name.$r.json" --overwrite > /dev/null
      cmp -s "$out/$name.$ext" "$out/plain.$ext" || { echo "$name: the frame differs" >&2; exit 1; }
    done
  done
done
python3 - "$out" <<'PY'
import glob, json, os, statistics, sys
out = sys.argv[1]
rows = {}
for f in sorted(glob.glob(os.path.join(out, "*.json"))):
    name = os.path.basename(f).rsplit(".", 2)[0]
    d = json.load(open(f))
    busy = [r["busy_seconds"] / d["render_seconds"] for r in d.get("ranks", [])]
    rows.setdefault(name, []).append((d["render_seconds"], busy[1] if busy else float("nan")))
print("| run | render s, median (range) | rank 1 busy / frame, median |")
print("|---|---|---|")
for name, v in sorted(rows.items()):
    s = [x[0] for x in v]
    print(f"| {name} | {statistics.median(s):.4f} ({min(s):.4f}-{max(s):.4f}) | {statistics.median(x[1] for x in v):.2f} |")
PY
