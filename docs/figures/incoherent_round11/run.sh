#!/bin/bash
# The eleventh round's measures (docs/INCOHERENT.md), from the repository root. OLD and NEW are build
# folders of main before (a22158e) and after the step-wise walk and the paired traversal.
OLD=${OLD:-/tmp/old/build} NEW=${NEW:-build} out=docs/figures/incoherent_round11
S="--scenes-dir ../shared/scenes"
# 1. The single-ray kernel, now a loop over bvh_step: old against new, three rounds (a b b a a b).
for kind in random frame; do
  python3 bench/ab_compare.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --rounds 3 \
    --json $out/ab_${kind}.json -- $S --scenes sponza sibenik bunny teapot --size 256x256 --repeats 9 \
    --builds 1 --clock cpu --rays $kind --configs embree:single embree:packet8 bvh
done
# 2. One ray at a time against two (bvh:paired), in the same runs, Embree beside them; the four
#    shared scenes and two forests whose trees (15 and 75 MiB) outgrow more of the caches.
for r in 1 2; do for kind in random ao diffuse frame; do
  $NEW/bench/cellrt_bench $S --scenes sponza sibenik bunny teapot 'builtin:forest?tris=200000' \
    'builtin:forest?tris=1000000' --size 256x256 --repeats 7 --builds 1 --clock cpu --rays $kind \
    --configs embree:single embree:packet8 bvh bvh:paired --json $out/paired_${kind}_$r.json > /dev/null
done; done
python3 $out/summary.py $out/ab_random.json $out/ab_frame.json
python3 $out/paired.py $out/paired_*.json
# 3. `auto`, whose BVH path is now bvh:paired: old against new, three rounds.
for kind in random ao diffuse frame; do
  python3 bench/ab_compare.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --rounds 3 \
    --json $out/ab_auto_${kind}.json -- $S --scenes sponza sibenik bunny teapot --size 256x256 --repeats 9 \
    --builds 1 --clock cpu --rays $kind --configs embree:single embree:packet8 auto
done
python3 $out/summary.py $out/ab_auto_random.json $out/ab_auto_ao.json $out/ab_auto_diffuse.json $out/ab_auto_frame.json
# 4. Instructions (callgrind; AVX2 under valgrind): the one-ray kernel old against new, and in the
#    new binary one ray against two (the file's "old" and "new" are then the same binary).
python3 bench/ab_callgrind.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --json $out/callgrind_single.json -- \
  $S --scenes sponza --configs bvh bvh:paired --size 64x64 --builds 1 --repeats 1 --rays random
python3 bench/ab_callgrind.py $NEW/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --json $out/callgrind_paired.json -- \
  $S --scenes sponza --configs bvh bvh:paired --size 64x64 --builds 1 --repeats 1 --rays random
