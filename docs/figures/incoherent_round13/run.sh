#!/bin/sh
# Thirteenth round (issue 18): the BVH's rays set up eight at a time in lanes.
# OLD: cellrt_bench of 4bba393, the commit before the round (git worktree add /tmp/old 4bba393, built with
# -DCELLRT_CUDA=OFF -DCELLRT_TESTS=OFF); NEW: this round's last commit (ed69f79). Run from the repository root.
OLD=${OLD:-/tmp/ab/old_bench}
NEW=${NEW:-build/bench/cellrt_bench}
D=docs/figures/incoherent_round13
for k in random ao frame diffuse; do
  python3 bench/ab_compare.py $OLD $NEW --overwrite --rounds 3 --json $D/ab_$k.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 --repeats 5 --builds 1 \
    --clock cpu --rays $k --configs embree:single embree:packet8 embree:packet16 bvh:paired bvh:stream bvh:packet auto \
    | grep '|' > $D/ab_$k.md
done
