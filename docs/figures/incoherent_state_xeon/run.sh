#!/bin/sh
# Where issue 18's targets stand on this machine: one thread, every ray kind, four scenes.
B=${B:-build/bench/cellrt_bench}
for kind in frame ao diffuse random; do
  for r in 1 2; do
    $B --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
      --clock cpu --rays $kind --configs embree:single embree:packet8 auto bvh bvh:packet kd:rec kd:branched \
      --json state_${kind}_$r.json > /dev/null 2>&1
  done
done
# The table (summary.md), from this folder: python3 ../../../bench/incoherent_state_table.py > summary.md
