#!/bin/sh
# Seventeenth round (docs/INCOHERENT.md): the near child's side from the octant in a register.
# /tmp/kdwide/cellrt_bench.old is main before the change (35d6a72), build/bench/cellrt_bench the
# change (48c59b7). Run from the repository root on an otherwise idle machine.
D=docs/figures/kd_octant
OLD=/tmp/kdwide/cellrt_bench.old
NEW=build/bench/cellrt_bench
python3 bench/ab_compare.py $OLD $NEW --overwrite --rounds 3 --json $D/ab_frame.json -- \
  --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
  --clock cpu --rays frame --configs embree:single kd:rec kd:branched kd:branchless bih:branched | grep '^|' > $D/ab_frame.md
for rays in random ao; do
  python3 bench/ab_compare.py $OLD $NEW --overwrite --rounds 2 --json $D/ab_$rays.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
    --clock cpu --rays $rays --configs embree:single kd:rec kd:branched bih:branched kd+auto | grep '^|' > $D/ab_$rays.md
done
# Speed over rtcIntersect1 / rtcOccluded1 in the same runs, old (a) and new (b):
for side in a b; do python3 $D/ratios.py $D/ab_frame.json $side > $D/ratios_frame_$side.txt; done
# Instructions of one timed pass (deterministic):
python3 bench/ab_callgrind.py $OLD $NEW --overwrite --json $D/callgrind_frame.json -- --scenes-dir ../shared/scenes --scenes sponza bunny \
  --size 128x128 --repeats 1 --builds 1 --rays frame --configs kd:rec kd:branched kd:branchless bih:branched \
  | grep '^|' > $D/callgrind_frame.md
