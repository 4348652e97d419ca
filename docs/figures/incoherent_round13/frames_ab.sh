#!/bin/sh
# Whole frames, old binary against new, turns a b b a a b: cellrt_scaling of 4bba393 (OLD_SCALING, built as
# run.sh says) and of this round's last commit. Run from the repository root.
OLD=${OLD_SCALING:-/tmp/old/build/bench/cellrt_scaling}
NEW=${NEW_SCALING:-build/bench/cellrt_scaling}
D=docs/figures/incoherent_round13
n=0
for who in a b b a a b; do
  n=$((n + 1))
  [ $who = a ] && B=$OLD || B=$NEW
  for s in direct ao; do
    $B --scenes-dir ../shared/scenes --scenes sponza sibenik bunny --configs embree:packet8 auto bvh:packet \
      --dispatch pull --packets 16 --workers 1 2 --repeats 3 --size 384x384 --shading $s \
      --json $D/frames_${who}_${s}_$n.json > /dev/null 2>&1
  done
done
python3 docs/figures/incoherent_round12/frames_table.py $D/frames_*.json > $D/frames_ab.md
