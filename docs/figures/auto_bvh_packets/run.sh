#!/bin/sh
# The fourteenth round (docs/INCOHERENT.md): `auto` over one wide BVH (packets=bvh) against `auto` over
# the kd-tree's packets and the BVH (packets=kd, its default), in the same runs. From the repository root.
D=docs/figures/auto_bvh_packets
# 1. Both routes in the same runs, beside Embree's single rays and packets of 8 and 16 (state table).
CONFIGS="embree:single embree:packet8 embree:packet16 auto auto@packets=bvh bvh:packet bvh:paired kd:rec" \
  bench/incoherent_state.sh $D
# 2. Builds, one and two threads, two runs each (builds_table.py).
for t in 1 2; do for r in 1 2; do
  build/bench/cellrt_bench --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 16x16 \
    --repeats 1 --builds 3 --threads $t --clock wall --configs embree:single auto auto@packets=bvh \
    --json $D/builds_t${t}_$r.json > /dev/null 2>&1
done; done
python3 $D/builds_table.py $D/builds_t*.json > $D/builds.md
# 3. Whole frames, both routes in the same runs (frames.md).
$D/frames.sh
