#!/bin/bash
# The eighth round's measures (docs/INCOHERENT.md): main before (OLD, befbd8a) and after the route's
# post-stratified times (NEW), from the repository root, OLD and NEW each a build folder.
OLD=${OLD:-/tmp/old/build} NEW=${NEW:-build} out=docs/figures/incoherent_round8
for kind in frame ao diffuse random; do
  python3 bench/ab_compare.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --rounds 3 \
    --json $out/ab_${kind}.json -- --scenes-dir ../shared/scenes \
    --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 --clock cpu --rays $kind \
    --configs embree:single embree:packet8 auto bvh:packet
done
# Whole frames with two workers, old and new in turn (a b b a a b).
for shading in direct ao diffuse; do
  for side in a b b a a b; do
    n=$(ls $out/two_${shading}_${side}_*.json 2>/dev/null | wc -l)
    bin=$OLD/bench/cellrt_scaling; [ $side = b ] && bin=$NEW/bench/cellrt_scaling
    $bin --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
      --configs embree:packet8 auto --dispatch pull --packets 16 --workers 2 \
      --size 512x512 --repeats 5 --shading $shading --json $out/two_${shading}_${side}_$((n + 1)).json
  done
done
python3 $out/summary.py
