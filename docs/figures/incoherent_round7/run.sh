#!/bin/bash
# A/B of the route: old (interleaved runs, 4 paths) and new (paired batches), the binaries in turn.
cd /tmp/m8
for kind in frame ao diffuse random; do
  n=0
  for b in old new new old old new; do
    n=$((n+1))
    ./bench_$b --scenes-dir /work/shared/scenes --scenes sponza sibenik bunny teapot --size 256x256 \
      --repeats 5 --builds 1 --clock cpu --rays $kind \
      --configs embree:single embree:packet8 auto auto@packets=bih-sah bvh:packet --json ${b}_${kind}_$n.json > log_${b}_${kind}_$n.txt 2>&1
  done
done
for sh in direct ao diffuse; do
  n=0
  for b in old new new old old new; do
    n=$((n+1))
    ./scaling_$b --scenes-dir /work/shared/scenes --scenes sponza sibenik bunny teapot --configs embree:packet8 auto \
      --dispatch pull --packets 16 --workers 2 --size 512x512 --repeats 5 --shading $sh --json two_${b}_${sh}_$n.json > logs_${b}_${sh}_$n.txt 2>&1
  done
done
echo done > finished
