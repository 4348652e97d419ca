#!/bin/bash
# The ninth round's measures (docs/INCOHERENT.md), from the repository root; OLD and NEW are build
# folders of main before (4698972) and after the BVH's spatial splits.
OLD=${OLD:-/tmp/old/build} NEW=${NEW:-build} out=docs/figures/incoherent_round9
# 1. The same binary, the BVH with and without spatial splits in the same runs.
NEW=$NEW $out/run_same_binary.sh
python3 $out/summary_same.py
# 2. Instructions and simulated misses of the BVH's kernels, old binary against new.
for kind in random ao; do
  python3 bench/ab_callgrind.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --cache-sim --overwrite \
    --json $out/callgrind_$kind.json -- --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs bvh bvh:packet --size 128x128 --builds 1 --repeats 1 --rays $kind
done
# 3. `auto` (whose BVH takes the default) old against new, three rounds (a b b a a b), on the two scenes
#    whose trees change.
for kind in frame ao diffuse random; do
  python3 bench/ab_compare.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --rounds 3 \
    --json $out/ab_${kind}.json -- --scenes-dir ../shared/scenes \
    --scenes sponza sibenik --size 256x256 --repeats 5 --builds 1 --clock cpu --rays $kind \
    --configs embree:single embree:packet8 auto bvh:packet
done
python3 $out/summary.py
