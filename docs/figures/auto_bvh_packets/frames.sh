#!/bin/sh
# Whole frames, `auto` (the kd-tree's packets and the BVH) against `auto@packets=bvh` (the BVH alone) in
# the same runs: cellrt_scaling at 384 x 384, 16 x 16 packets, pull dispatch, one and two workers, direct,
# AO and diffuse shading, three rounds, Embree's packets of eight and the BVH's packets beside them;
# then frames_table.py as frames.md. From the repository root:
#   docs/figures/auto_bvh_packets/frames.sh [CELLRT_SCALING]
D=docs/figures/auto_bvh_packets
B=${1:-build/bench/cellrt_scaling}
for n in 1 2 3; do
  for s in direct ao diffuse; do
    $B --scenes-dir ../shared/scenes --scenes sponza sibenik bunny \
      --configs embree:packet8 auto auto@packets=bvh bvh:packet \
      --dispatch pull --packets 16 --workers 1 2 --repeats 3 --size 384x384 --shading $s \
      --json $D/frames_${s}_$n.json > /dev/null 2>&1
  done
done
python3 $D/frames_table.py $D/frames_*_[123].json > $D/frames.md
