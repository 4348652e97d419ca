#!/bin/sh
# Sixteenth round (docs/INCOHERENT.md): the BVH's children by decreasing box area. Old and new
# cellrt_bench copied to /tmp/ab first (bench_base: main before the change, 5224d04; bench_v1: the
# change; bench_v2: the same slot order with the nodes laid out in the collapse's order, not kept).
# Run from the repository root.
D=docs/figures/any_hit_order
for rays in random ao frame diffuse; do
  bench/ab_compare.py /tmp/ab/bench_base /tmp/ab/bench_v1 --overwrite --rounds 2 --json $D/ab_$rays.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs embree:single embree:packet8 bvh:paired bvh:packet bvh:stream auto \
    --size 256x256 --repeats 5 --builds 1 --clock cpu --rays $rays | grep '^|' > $D/ab_$rays.md
done
for rays in random frame; do
  bench/ab_compare.py /tmp/ab/bench_base /tmp/ab/bench_v2 --overwrite --rounds 2 --json $D/ab2_$rays.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs embree:single embree:packet8 bvh:paired bvh:packet bvh:stream auto \
    --size 256x256 --repeats 5 --builds 1 --clock cpu --rays $rays | grep '^|' > $D/ab2_$rays.md
done
bench/ab_compare.py /tmp/ab/bench_v1 /tmp/ab/bench_v2 --overwrite --rounds 3 --json $D/ab_v1v2_frame.json -- \
  --scenes-dir ../shared/scenes --scenes sponza sibenik bunny --configs embree:single bvh:paired bvh:packet \
  --size 256x256 --repeats 5 --builds 1 --clock cpu --rays frame
bench/incoherent_state.sh $D    # the state table: summary.md
python3 /split.py $D docs/figures/incoherent_round13   # closest and any hits apart
# The forest, and the nearest child's ties to the smallest box (bench_v3: nearest_lane's key with the
# lane order reversed; not kept):
for rays in random frame; do
  bench/ab_compare.py /tmp/ab/bench_base /tmp/ab/bench_v1 --overwrite --rounds 2 --json $D/ab_forest_$rays.json -- \
    --scenes-dir ../shared/scenes --scenes 'builtin:forest?tris=200000' \
    --configs embree:single embree:packet8 bvh:paired bvh:packet bvh:stream auto \
    --size 256x256 --repeats 5 --builds 1 --clock cpu --rays $rays
done
bench/ab_compare.py /tmp/ab/bench_v1 /tmp/ab/bench_v3 --overwrite --rounds 2 --json $D/ab_v1v3_frame.json -- \
  --scenes-dir ../shared/scenes --scenes sponza sibenik bunny 'builtin:forest?tris=200000' \
  --configs embree:single bvh:paired bvh:wide --size 256x256 --repeats 5 --builds 1 --clock cpu --rays frame
# Not kept either: bench_v5, the closest-hit pushes reversed (pops largest box first); bench_s1, the
# streams' any-hit keys by slot instead of distance.
bench/ab_compare.py /tmp/ab/bench_v1 /tmp/ab/bench_v5 --overwrite --rounds 2 --json $D/ab_v1v5_frame.json -- \
  --scenes-dir ../shared/scenes --scenes sponza sibenik bunny 'builtin:forest?tris=200000' \
  --configs embree:single bvh:paired --size 256x256 --repeats 5 --builds 1 --clock cpu --rays frame
for rays in random ao; do
  bench/ab_compare.py /tmp/ab/bench_v1 /tmp/ab/bench_s1 --overwrite --rounds 2 --json $D/ab_stream_$rays.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:single bvh:stream \
    --size 256x256 --repeats 5 --builds 1 --clock cpu --rays $rays
done
# Whole frames, old cellrt_scaling (5224d04, built in a worktree) against the new one:
bench/frames_ab.sh $D/frames /tmp/ab/scaling_base
