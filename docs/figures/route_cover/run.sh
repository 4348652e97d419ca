#!/bin/sh
# docs/INCOHERENT.md, "Twentieth round": the route's runs and classes. From the repository root, with
# OLD the build directory of the commit before the round (d2541d2; its bench/scaling_bench.cpp
# replaced by this round's, so that both interleave their structures) and build/ the route measured.
# Each folder below held one route as b (or c); a is the old one in the same turns.
OLD=${OLD:?the old build directory}
D=docs/figures/route_cover
# sequential/: before cellrt_scaling interleaved its structures, direct frames, a b b a a b
# (the old bench/scaling_bench.cpp in both builds).
# interleaved_02/ (classes covered at 2 %, every fourth run), cover_mix/ (5 %, backing off),
# pairs/ (paths compared two at a time), kept/ (the BVH's single rays left out of coherent batches):
n=0
for who in a b b a; do
  n=$((n + 1))
  [ $who = a ] && B=$OLD/bench/cellrt_scaling || B=build/bench/cellrt_scaling
  for s in direct ao diffuse; do
    $B --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
      --configs embree:packet16 auto kd+auto bvh:packet --dispatch pull --packets 16 --workers 1 \
      --repeats 7 --size 384x384 --shading $s --json $D/kept/f_${who}_${s}_$n.json > /dev/null 2>&1
  done
done
# Each of the other folders holds the same loop's output with its own build as b (interleaved_02/
# and cover_mix/ six turns, a b b a a b); affinity/ (not kept): its build alone, three runs, as f_c_*.
# first_frame/: one frame per process, the route learning within it, in turns a b b a, six times
# (cover_mix.txt and pairs.txt: the same with those folders' builds):
: > $D/first_frame/kept.txt
for i in 1 2 3 4 5 6; do
  for who in a b b a; do
    [ $who = a ] && B=$OLD/cellrt || B=build/cellrt
    for s in sponza sibenik bunny teapot; do
      for acc in auto bvh:packet kd; do
        line=$($B render ../shared/scenes/$s/$s.json --accel $acc --threads 1 --size 384x384 \
          -o /tmp/route_cover.png --overwrite 2>&1 | grep -o "render [0-9.]* s")
        echo "$who $s $acc $line" >> $D/first_frame/kept.txt
      done
    done
  done
done
# first_three/: the route after three frames (the warm-up and a timed pair), old (a) and new (b):
for i in 1 2 3; do
  for who in a b; do
    [ $who = a ] && B=$OLD/bench/cellrt_scaling || B=build/bench/cellrt_scaling
    $B --scenes-dir ../shared/scenes --scenes bunny teapot sponza sibenik --configs auto --dispatch pull \
      --packets 16 --workers 1 --repeats 1 --size 384x384 --shading direct --json $D/first_three/${who}_$i.json
  done
done
# packets_bvh/: the old route with packets=bvh, the single rays' time on coherent batches:
for s in direct ao diffuse; do
  $OLD/bench/cellrt_scaling --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs auto@packets=bvh --dispatch pull --packets 16 --workers 1 --repeats 3 --size 384x384 \
    --shading $s --json $D/packets_bvh/old_$s.json
done
# two_workers/: whole frames with one and two workers against Embree's fastest, the kept route:
for s in ao diffuse; do
  build/bench/cellrt_scaling --scenes-dir ../shared/scenes --scenes sponza sibenik bunny teapot \
    --configs embree:single embree:packet8 embree:packet16 auto --dispatch pull --packets 16 \
    --workers 1 2 --repeats 7 --size 384x384 --shading $s --json $D/two_workers/scaling_$s.json
done
python3 $D/tables.py > $D/tables.md
