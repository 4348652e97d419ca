#!/bin/sh
# Where issue 18's targets stand after the eleventh round: one thread, every ray kind, four scenes
# (the Xeon folder's run.sh with bvh:paired added). Run in this folder, B the bench from the root.
B=${B:-../../../build/bench/cellrt_bench}
for kind in frame ao diffuse random; do
  for r in 1 2; do
    $B --scenes-dir ../../../../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
      --clock cpu --rays $kind --configs embree:single embree:packet8 auto bvh bvh:paired bvh:packet kd:rec kd:branched \
      --json state_${kind}_$r.json > /dev/null 2>&1
  done
done
python3 ../../../bench/incoherent_state_table.py > summary.md
# Whole frames, one and two workers (from the repository root):
#   for s in ao diffuse; do build/bench/cellrt_scaling --scenes-dir ../shared/scenes --scenes sponza bunny \
#     --configs embree:single embree:packet8 auto bvh:paired --dispatch pull --packets 16 --workers 1 2 \
#     --repeats 3 --size 384x384 --shading $s --json docs/figures/incoherent_state_zen4_r11/scaling_$s.json; done
#   python3 docs/figures/incoherent_state_zen4_r11/scaling_table.py docs/figures/incoherent_state_zen4_r11/scaling_*.json
