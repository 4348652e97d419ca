#!/bin/bash
# bench_new: this branch's build/bench/cellrt_bench (75894f0).
S=/work/shared/scenes
for r in 1 2; do
  for sc in teapot bunny sponza sibenik 'builtin:forest?tris=1000000'; do
    tag=$(echo "$sc" | sed 's/builtin:forest?tris=1000000/forest1M/')
    uptime >> load2.txt
    ./bench_new --scenes-dir $S --scenes "$sc" --size 128x128 --repeats 3 --builds 5 --clock cpu --threads 1 --configs embree kd@clip_ratio=0,max_bad_refines=3 kd --json ab_${tag}_r$r.json > ab_${tag}_r$r.txt 2>&1
    echo "$tag r$r"; grep '^| kd' ab_${tag}_r$r.txt | cut -d'|' -f2,3,4,7
  done
done
