#!/bin/bash
# The tenth round's measures (docs/INCOHERENT.md), from the repository root; OLD and NEW are build
# folders of main before (92e2ccb) and after the integer lane minimum.
OLD=${OLD:-/tmp/old/build} NEW=${NEW:-build} out=docs/figures/incoherent_round10
# 1. Time: old against new, four rounds (a b b a a b b a), Embree in every run.
for kind in random diffuse frame; do
  python3 bench/ab_compare.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --rounds 4 \
    --json $out/ab_${kind}.json -- --scenes-dir ../shared/scenes \
    --scenes sponza sibenik bunny teapot --size 256x256 --repeats 9 --builds 1 --clock cpu --rays $kind \
    --configs embree:single embree:packet8 bvh auto
done
# 1b. The same at 512 x 512 (random and diffuse rays), the files ab512_*.json.
for kind in random diffuse; do
  python3 bench/ab_compare.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --overwrite --rounds 4 \
    --json $out/ab512_${kind}.json -- --scenes-dir ../shared/scenes \
    --scenes sponza sibenik bunny teapot --size 512x512 --repeats 9 --builds 1 --clock cpu --rays $kind \
    --configs embree:single embree:packet8 bvh auto
done
# 2. Instructions and simulated misses of the BVH's single rays.
python3 bench/ab_callgrind.py $OLD/bench/cellrt_bench $NEW/bench/cellrt_bench --cache-sim --overwrite \
  --json $out/callgrind_random.json -- --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
  --configs bvh --size 128x128 --builds 1 --repeats 1 --rays random
python3 $out/summary.py $out/ab_random.json $out/ab_diffuse.json $out/ab_frame.json $out/ab512_random.json $out/ab512_diffuse.json
