#!/bin/sh
# The fifteenth round (docs/INCOHERENT.md; tried, not kept): the route's learning cost, old build
# (5fb8386's Python module, at $OLD/python) against new (build/python: 5fb8386 with the learning runs'
# drop of clear losers, whose code is not in the repository), a fresh accelerator's first call over its
# second, runs in turn old new new old; then table.py as table.md; then the bench's A/B of the same
# two builds (ab_frame, ab_ao). From the repository root.
D=docs/figures/route_drop
for s in sponza bunny; do
  n=0
  for who in old new new old; do
    n=$((n + 1))
    [ $who = old ] && P=${OLD:?the old build folder}/python || P=build/python
    PYTHONPATH=$P /usr/bin/python3 $D/first_call.py ../shared/scenes/$s/$s.json $D/first_call_${s}_${who}_$n.json --rounds 5
  done
done
(cd $D && python3 table.py > table.md)
for k in frame ao; do
  python3 bench/ab_compare.py $OLD/bench/cellrt_bench build/bench/cellrt_bench --overwrite --rounds 2 --json $D/ab_$k.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
    --clock cpu --rays $k --configs embree:packet16 auto auto@packets=bvh 2>/dev/null | grep "^|" > $D/ab_$k.md
done
# The second trial (docs/INCOHERENT.md, fifteenth round): 5fb8386 with every timed run after learning
# first weighing the sums before it by 0.75 ($DECAY: that build's cellrt_bench), against 5fb8386, in
# turn old new new old, 24 passes each (decay_*.json).
n=0
for who in old new new old; do
  n=$((n + 1))
  [ $who = old ] && B=$OLD/bench/cellrt_bench || B=${DECAY:?the decaying build}
  $B --scenes-dir ../shared/scenes --scenes sponza sibenik bunny --size 256x256 --repeats 24 --builds 1 --clock cpu \
    --rays frame --configs kd+auto bvh:packet auto --json $D/decay_${who}_$n.json > /dev/null 2>&1
done
