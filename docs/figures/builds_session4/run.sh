#!/bin/sh
# Build times beside Embree's, e5aeff0's benchmark against this session's, in turn, three rounds.

for r in 1 2 3; do
  for v in old new; do
    if [ $v = old ]; then B=${OLD:-old}/bench/cellrt_bench; else B=${NEW:-build}/bench/cellrt_bench; fi
    $B --scenes-dir ../shared/scenes --scenes teapot bunny sponza sibenik 'builtin:forest?tris=200000' \
      --configs embree:single kd:branched bvh --size 16x16 --repeats 1 --builds 5 --clock cpu --threads 1 \
      --json builds_${v}_$r.json > /dev/null 2>&1
  done
done
