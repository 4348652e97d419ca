#!/bin/sh
# Whole frames, an old build against a new one, in turns a b b a a b: cellrt_scaling at 384 x 384, 16 x 16
# packets, pull dispatch, one and two workers, direct and AO shading, Sponza, Sibenik and the bunny, with
# Embree's packets of eight in every run; then the table (frames_table.py) as frames_ab.md. From the
# repository root:
#   bench/frames_ab.sh OUT_DIR OLD_CELLRT_SCALING [NEW_CELLRT_SCALING]
set -e
D=${1:?usage: bench/frames_ab.sh OUT_DIR OLD_CELLRT_SCALING [NEW_CELLRT_SCALING]}
OLD=${2:?the cellrt_scaling of the old build}
NEW=${3:-build/bench/cellrt_scaling}
n=0
for who in a b b a a b; do
  n=$((n + 1))
  [ $who = a ] && B=$OLD || B=$NEW
  for s in direct ao; do
    $B --scenes-dir ../shared/scenes --scenes sponza sibenik bunny --configs embree:packet8 auto bvh:packet \
      --dispatch pull --packets 16 --workers 1 2 --repeats 3 --size 384x384 --shading $s \
      --json $D/frames_${who}_${s}_$n.json > /dev/null
  done
done
python3 "$(dirname "$0")/frames_table.py" $D/frames_*.json > $D/frames_ab.md
