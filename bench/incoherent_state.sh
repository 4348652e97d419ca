#!/bin/sh
# Where issue 18's targets stand: every ray kind of cellrt_bench (frame, ao, diffuse, random), two runs
# each, the four shared scenes at 256 x 256, one thread, Embree's single rays and packets beside cellrt's
# paths in the same runs; then the table of speed ratios (incoherent_state_table.py) as summary.md.
# Run from the repository root:
#   bench/incoherent_state.sh OUT_DIR [CELLRT_BENCH]     (CONFIGS="..." to change the configurations)
set -e
D=${1:?usage: bench/incoherent_state.sh OUT_DIR [CELLRT_BENCH]}
B=${2:-build/bench/cellrt_bench}
CONFIGS=${CONFIGS:-embree:single embree:packet8 embree:packet16 auto bvh:wide bvh:paired bvh:packet kd:rec kd:branched}
for k in frame ao diffuse random; do
  for r in 1 2; do
    $B --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
      --clock cpu --rays $k --configs $CONFIGS --json $D/state_${k}_$r.json > /dev/null
  done
done
T=$(cd "$(dirname "$0")" && pwd)/incoherent_state_table.py
(cd "$D" && python3 "$T" > summary.md)
