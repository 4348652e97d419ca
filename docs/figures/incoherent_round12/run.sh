#!/bin/sh
# Twelfth round (issue 18): the BVH's packets and streams fetch the children they push.
# OLD: cellrt_bench of 03e562a, the commit before the round (git worktree add /tmp/old 03e562a, built with -DCELLRT_CUDA=OFF
# -DCELLRT_TESTS=OFF); NEW: this commit's. Run from the repository root.
OLD=${OLD:-/tmp/ab/cellrt_bench.old}
NEW=${NEW:-build/bench/cellrt_bench}
D=docs/figures/incoherent_round12
for k in frame ao diffuse random; do
  python3 bench/ab_compare.py $OLD $NEW --overwrite --rounds 3 --json $D/ab_$k.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
    --clock cpu --rays $k --configs embree:single embree:packet8 bvh:packet bvh:stream auto | grep '|' > $D/ab_$k.md
done
# Where the targets stand (bench/incoherent_state.sh; its `bvh:wide` was then named `bvh`), with Embree's
# packets of 16 (AVX-512 here) among its configurations.
bench/incoherent_state.sh $D $NEW
# The million-triangle forest (a 75 MiB tree, beyond the 32 MiB L3), old against new:
for k in frame ao; do
  python3 bench/ab_compare.py $OLD $NEW --overwrite --rounds 3 --json $D/ab_forest_$k.json -- \
    --scenes 'builtin:forest?tris=1000000' --size 256x256 --repeats 5 --builds 1 \
    --clock cpu --rays $k --configs embree:packet8 embree:packet16 bvh:packet bvh:stream | grep '|' > $D/ab_forest_$k.md
done
# The kd-tree's leaves in SIMD lanes (INCOHERENT.md, twelfth round): the branch kd-lane-leaves-prototype
# built in /tmp/proto (-DCELLRT_CUDA=OFF -DCELLRT_TESTS=OFF), its binary without and with CELLRT_KD_LANES=1
# (a wrapper script: CELLRT_KD_LANES=1 exec /tmp/proto/build/bench/cellrt_bench "$@"), one kd config a run
# (the prototype's blocks belong to the last kd-tree built):
#   for c in kd:rec kd:branched; do python3 bench/ab_compare.py /tmp/proto/build/bench/cellrt_bench lanes.sh \
#     --rounds 3 -- --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 \
#     --builds 1 --clock cpu --rays frame --configs embree:single $c; done
