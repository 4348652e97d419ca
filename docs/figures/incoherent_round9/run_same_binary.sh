#!/bin/bash
# The ninth round's same-run comparison: the new binary's BVH with and without spatial splits
# (split_budget=0 is the old tree, byte for byte), its single-ray and packet kernels, beside Embree's
# fastest, configurations interleaved within each run; two runs per ray kind.
NEW=${NEW:-build} out=docs/figures/incoherent_round9
for run in 1 2; do
  for kind in frame ao diffuse random; do
    $NEW/bench/cellrt_bench --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
      --size 256x256 --repeats 5 --builds 3 --clock cpu --rays $kind \
      --configs embree:single embree:packet8 bvh@split_budget=0 bvh bvh:packet@split_budget=0 bvh:packet \
      --json $out/same_${kind}_$run.json
  done
done
