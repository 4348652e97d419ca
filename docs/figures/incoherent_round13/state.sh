#!/bin/sh
# Where issue 18's targets stand after the thirteenth round: the eleventh round's state script over this
# round's binary, two runs per ray kind, Embree's packets of 16 among its configurations. `bvh` there was
# the one-ray kernel; since 2026-12-05 `bvh`'s default traversal is `paired`: rerun with `bvh:wide` in its place.
NEW=${NEW:-build/bench/cellrt_bench}
D=docs/figures/incoherent_round13
for k in frame ao diffuse random; do
  for r in 1 2; do
    $NEW --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
      --clock cpu --rays $k --configs embree:single embree:packet8 embree:packet16 auto bvh bvh:paired bvh:packet kd:rec kd:branched \
      --json $D/state_${k}_$r.json > /dev/null 2>&1
  done
done
(cd $D && python3 ../incoherent_state_xeon/summary.py > summary.md)
