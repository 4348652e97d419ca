#!/bin/sh
# The wide BVH's packets of sixteen rays with AVX-512 (docs/INCOHERENT.md, "Nineteenth round").
# OLD: cellrt_bench built at d42f0ce (packets of eight everywhere); NEW: at the commit that made them sixteen.
# Run from the repository root.
OLD=${1:?usage: run.sh OLD/cellrt_bench NEW/cellrt_bench [ROUTE_OLD ROUTE_NEW]}; NEW=${2:?}
D=docs/figures/packet16
for rays in ao frame diffuse; do
  bench/ab_compare.py $OLD $NEW --overwrite --rounds 2 --json $D/time_$rays.json -- --scenes-dir ../shared/scenes \
    --scenes sponza sibenik bunny teapot --size 256x256 --repeats 3 --builds 1 --rays $rays --clock cpu \
    --configs embree:packet16 bvh:packet auto
done
python3 $D/ratio.py > $D/ratio.md
bench/incoherent_state.sh $D/state $NEW
# The route leaving the kd-tree's packets out of incoherent batches (route_*.json, state_route/):
# ROUTE_OLD, the binary of the packets' commit, against ROUTE_NEW, the route's; given as the third
# and fourth arguments.
ROUTE_OLD=$3; ROUTE_NEW=$4
[ -n "$ROUTE_NEW" ] || exit 0
for i in 1 2; do  # auto against auto@packets=bvh on Sibenik's AO rays, the old route
  $ROUTE_OLD --scenes-dir ../shared/scenes --scenes sibenik --size 256x256 --repeats 3 --builds 1 --rays ao \
    --clock cpu --configs embree:packet16 bvh:packet bvh:stream auto auto@packets=bvh --json $D/route_sib_$i.json
done
for rays in ao diffuse random frame; do
  bench/ab_compare.py $ROUTE_OLD $ROUTE_NEW --overwrite --rounds 2 --json $D/route_$rays.json -- --scenes-dir ../shared/scenes \
    --scenes sponza sibenik bunny teapot --size 256x256 --repeats 3 --builds 1 --rays $rays --clock cpu \
    --configs embree:packet16 auto
done
bench/incoherent_state.sh $D/state_route $ROUTE_NEW
# Whole frames, one and two workers, two runs of seven repeats each (scaling_*_{1,2}.json, scaling.md),
# with the route's binary (build/bench/cellrt_scaling of the same commit):
S=$(dirname "$ROUTE_NEW")/cellrt_scaling
for r in 1 2; do
  for s in ao diffuse; do
    $S --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
      --configs embree:single embree:packet8 embree:packet16 auto bvh:packet --dispatch pull --packets 16 \
      --workers 1 2 --repeats 7 --size 384x384 --shading $s --json $D/scaling_${s}_$r.json
  done
done
python3 $D/scaling_table.py $D/scaling_ao_1.json $D/scaling_ao_2.json $D/scaling_diffuse_1.json \
  $D/scaling_diffuse_2.json > $D/scaling.md
# Eight rays a packet (AVX2's kernels) against sixteen (AVX-512's) in the same binary, two runs
# (width_ao_*.json), the route's binary:
for r in 1 2; do
  $ROUTE_NEW --scenes-dir ../shared/scenes --scenes sponza sibenik --size 256x256 --repeats 5 --builds 1 \
    --rays ao --clock cpu --configs embree:packet8 embree:packet16 bvh:packet+avx2 bvh:packet+avx512 \
    --json $D/width_ao_$r.json
done
# Direct frames (the study's shading), one worker: the kd-tree's packets against the BVH's sixteen
# (direct_*.json):
for r in 1 2; do
  $S --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs embree:packet16 auto auto@packets=bvh kd+auto bvh:packet --dispatch pull --packets 16 \
    --workers 1 --repeats 7 --size 384x384 --shading direct --json $D/direct_$r.json
done
