#!/usr/bin/env bash
# Two cellrt binaries in turn (the order swapped every round): the plain program renders Sponza at
# 1920x1080 on THREADS threads, ROUNDS rounds, each pair of frames compared byte for byte; medians of
# --stats frame_seconds (the frame from its memory to its last pixel) and render_seconds (the
# tracing), and the median of the rounds' ratios (docs/SCALING.md, "The frame's memory").
# Usage: ab.sh OUT_DIR ROUNDS THREADS A=CELLRT B=CELLRT
set -euo pipefail
root="$(cd "$(dirname "$0")/../../.." && pwd)"
out=$1; rounds=$2; threads=$3; shift 3
scene="${CELLRT_SCENES:-$root/../shared/scenes}/sponza/sponza.json"
mkdir -p "$out"
for ((r = 0; r < rounds; ++r)); do
  specs=("$@")
  ((r % 2)) && specs=("$2" "$1")
  for spec in "${specs[@]}"; do
    "${spec#*=}" render "$scene" --size 1920x1080 --threads "$threads" -o "$out/${spec%%=*}.pfm" \
      --stats "$out/${spec%%=*}.$r.json" --overwrite > /dev/null
  done
  cmp "$out/${1%%=*}.pfm" "$out/${2%%=*}.pfm"
done
python3 - "$out" "$threads" "${1%%=*}" "${2%%=*}" <<'PY'
import glob, json, statistics, sys
out, threads, a, b = sys.argv[1:]
med = statistics.median
runs = {n: [json.load(open(f)) for f in sorted(glob.glob(f"{out}/{n}.*.json"))] for n in (a, b)}
for key in ("frame_seconds", "render_seconds"):
    x = [d[key] for d in runs[a]]
    y = [d[key] for d in runs[b]]
    print(f"| {threads} | {key} | {med(x):.4f} | {med(y):.4f} | {med(y) / med(x):.3f} | "
          f"{med([q / p for p, q in zip(x, y)]):.3f} | {len(x)} |")
PY
