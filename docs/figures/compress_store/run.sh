#!/bin/sh
# The twenty-first round (docs/INCOHERENT.md): the BVH's push compressed in a register, old binary
# (365fc29) against new, every ray kind, three rounds a b b a a b; then issue 18's state table.
# Run from the repository root: docs/figures/compress_store/run.sh OLD_BENCH
set -e
D=docs/figures/compress_store
OLD=${1:?usage: run.sh OLD/cellrt_bench}
for k in random ao diffuse frame; do
  python3 bench/ab_compare.py "$OLD" build/bench/cellrt_bench --overwrite --rounds 3 --json $D/ab_$k.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet8 bvh bvh:wide bvh:packet auto \
    --rays $k --repeats 5 --builds 1 --size 256x256 --clock cpu > $D/ab_$k.md
done
mkdir -p $D/state
bench/incoherent_state.sh $D/state
# two_workers/: whole frames, one and two workers, against Embree's fastest (as route_cover/two_workers/),
# with bvh:packet beside auto:
mkdir -p $D/two_workers
for s in ao diffuse; do
  build/bench/cellrt_scaling --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs embree:single embree:packet8 embree:packet16 auto bvh:packet --dispatch pull --packets 16 \
    --workers 1 2 --repeats 7 --size 384x384 --shading $s --json $D/two_workers/scaling_$s.json
done
python3 $D/two_workers/table.py > $D/two_workers/table.md
# mask_compare_*: the packets' box test's bits straight from the compare (bits_le), the binary before
# it (BEFORE_MASK, the push change alone) against the new one, two rounds:
if [ -n "$BEFORE_MASK" ]; then
  for k in ao frame; do
    python3 bench/ab_compare.py "$BEFORE_MASK" build/bench/cellrt_bench --overwrite --rounds 2 --json $D/mask_compare_$k.json -- \
      --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet16 bvh:packet \
      --rays $k --repeats 5 --builds 1 --size 256x256 --clock cpu > $D/mask_compare_$k.md
  done
fi
python3 docs/figures/kd_octant/state/kd_branched_ratio.py docs/figures/compress_store/state > docs/figures/compress_store/state/kd_branched_ratio.txt
# single_below/: kPacketSingleBelow (bvh_packet.inl) re-measured with the faster walks: binaries built
# with any hit ANY and closest hit CLOSEST in place of 3 and 1 (B_ANY_CLOSEST), against the kept one (B0):
for v in 5_1 8_1 3_2 3_3; do
  [ -x "$B_DIR/b_$v" ] || continue
  for k in ao frame diffuse; do
    python3 bench/ab_compare.py "$B_DIR/b0" "$B_DIR/b_$v" --overwrite --rounds 2 --json $D/single_below/${v}_$k.json -- \
      --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet16 bvh:packet \
      --rays $k --repeats 5 --builds 1 --size 256x256 --clock cpu > $D/single_below/${v}_$k.md
  done
done
# not_kept/wl_*: watertight_leaf marked [[gnu::always_inline]] (B_WL), against the kept build (B_BASE):
if [ -n "$B_WL" ]; then
  for k in random ao diffuse; do
    python3 bench/ab_compare.py "$B_BASE" "$B_WL" --overwrite --rounds 2 --json $D/not_kept/wl_$k.json -- \
      --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet8 bvh bvh:packet bvh:stream \
      --rays $k --repeats 5 --builds 1 --size 256x256 --clock cpu > $D/not_kept/wl_$k.md
  done
fi
# in_place/: the kd-tree's (and BIH's) packets made in place in trace_batch (B_IN_PLACE) against the
# build before it (B_BEFORE_IN_PLACE): instructions (callgrind, AVX2 under valgrind) and two timed runs.
if [ -n "$B_IN_PLACE" ]; then
  python3 bench/ab_callgrind.py "$B_BEFORE_IN_PLACE" "$B_IN_PLACE" --overwrite --json $D/in_place/callgrind_frame.json -- \
    --scenes-dir ../shared/scenes --scenes sponza bunny --configs kd+auto --rays frame --size 128x128 --repeats 1 --builds 1
  python3 bench/ab_compare.py "$B_BEFORE_IN_PLACE" "$B_IN_PLACE" --overwrite --rounds 3 --json $D/in_place/time_frame_1.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet16 kd+auto bih+auto \
    --rays frame --repeats 5 --builds 1 --size 256x256 --clock cpu
  python3 bench/ab_compare.py "$B_BEFORE_IN_PLACE" "$B_IN_PLACE" --overwrite --rounds 3 --json $D/in_place/time_frame_2.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet16 kd+auto \
    --rays frame --repeats 7 --builds 1 --size 256x256 --clock cpu
fi
# coherence/: batch_coherence over 16 pairs (B_PAIRS16) against 64 (B_PAIRS64): perf of auto on the
# teapot's random rays (perf.txt) and two A/B runs.
if [ -n "$B_PAIRS16" ]; then
  python3 bench/ab_compare.py "$B_PAIRS64" "$B_PAIRS16" --overwrite --rounds 3 --json $D/coherence/ab_random.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet8 bvh auto \
    --rays random --repeats 5 --builds 1 --size 256x256 --clock cpu
  python3 bench/ab_compare.py "$B_PAIRS64" "$B_PAIRS16" --overwrite --rounds 3 --json $D/coherence/ab_ao.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet16 bvh:packet auto \
    --rays ao --repeats 5 --builds 1 --size 256x256 --clock cpu
fi
mkdir -p $D/state_head && bench/incoherent_state.sh $D/state_head && python3 docs/figures/kd_octant/state/kd_branched_ratio.py $D/state_head > $D/state_head/kd_branched_ratio.txt   # at 148811a, before the packets' leaves in lanes
# leaf_lanes/: the packets' leaves tested in the rays' lanes (B_LL, 'as many rays as triangles') against
# the build before it (B_BEFORE_LL); B_LL2 the same with 'twice as many':
if [ -n "$B_LL" ]; then
  python3 bench/ab_callgrind.py "$B_BEFORE_LL" "$B_LL" --overwrite --json $D/leaf_lanes/callgrind_frame.json -- \
    --scenes-dir ../shared/scenes --scenes sponza bunny --configs bvh:packet --rays frame --size 128x128 --repeats 1 --builds 1
  python3 bench/ab_callgrind.py "$B_BEFORE_LL" "$B_LL" --overwrite --json $D/leaf_lanes/callgrind_ao.json -- \
    --scenes-dir ../shared/scenes --scenes sponza sibenik --configs bvh:packet --rays ao --size 128x128 --repeats 1 --builds 1
  for k in frame ao diffuse; do
    python3 bench/ab_compare.py "$B_BEFORE_LL" "$B_LL" --overwrite --rounds 3 --json $D/leaf_lanes/time_$k.json -- \
      --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet16 bvh:packet auto \
      --rays $k --repeats 5 --builds 1 --size 256x256 --clock cpu > $D/leaf_lanes/time_$k.md
    python3 bench/ab_compare.py "$B_LL" "$B_LL2" --overwrite --rounds 3 --json $D/leaf_lanes/time_ll2_vs_ll1_$k.json -- \
      --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet16 bvh:packet \
      --rays $k --repeats 5 --builds 1 --size 256x256 --clock cpu
  done
fi
# state_final/, two_workers_final/: the state and the whole frames at the round's last code commit.
mkdir -p $D/state_final $D/two_workers_final
bench/incoherent_state.sh $D/state_final
python3 docs/figures/kd_octant/state/kd_branched_ratio.py $D/state_final > $D/state_final/kd_branched_ratio.txt
for s in ao diffuse; do
  build/bench/cellrt_scaling --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs embree:single embree:packet8 embree:packet16 auto bvh:packet --dispatch pull --packets 16 \
    --workers 1 2 --repeats 7 --size 384x384 --shading $s --json $D/two_workers_final/scaling_$s.json
done
python3 $D/two_workers/table.py $D/two_workers_final > $D/two_workers_final/table.md
# leaf_lanes/callgrind_half_vs_kept.json: the lanes from half as many rays as triangles (B_LL_HALF):
[ -n "$B_LL_HALF" ] && python3 bench/ab_callgrind.py "$B_LL" "$B_LL_HALF" --overwrite --json $D/leaf_lanes/callgrind_half_vs_kept.json -- \
  --scenes-dir ../shared/scenes --scenes sponza bunny --configs bvh:packet --rays frame --size 128x128 --repeats 1 --builds 1
# leaf_lanes/callgrind_one_copy.json: one copy of the watertight test in lanes (B_ONE_COPY) against B_LL:
[ -n "$B_ONE_COPY" ] && python3 bench/ab_callgrind.py "$B_LL" "$B_ONE_COPY" --overwrite --json $D/leaf_lanes/callgrind_one_copy.json -- \
  --scenes-dir ../shared/scenes --scenes sponza --configs bvh:packet bvh kd+auto --rays frame --size 128x128 --repeats 1 --builds 1
