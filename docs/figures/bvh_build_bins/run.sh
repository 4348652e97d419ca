#!/bin/sh
# The BVH's object split passing over empty bins (docs/BVH.md, "Build"), measured. OLD and NEW are two
# checkouts' build folders (OLD: f36fb37); docs/figures/tree_hash.cpp is linked once with each one's
# src/bvh/bvh_build.cpp, as in ../bvh_spatial_reach/run.sh.
# 1. Instructions of the build (callgrind.txt), each binary's `cellrt info SCENE --accel bvh --threads 1`:
#    valgrind --tool=callgrind --callgrind-out-file=/dev/null --toggle-collect='cellrt::detail::build_bvh*' \
#        $OLD/cellrt info SCENE --accel bvh --threads 1        (and $NEW/cellrt)
# 2. The trees' bytes (tree_hash.txt): ./tree_hash bvh SCENE 3 1 with each builder.
# 3. Build time beside Embree's, the binaries in turn, three rounds, one and two threads (b_*.json, table.py):
set -e
for r in 1 2 3; do
  for v in old new; do
    if [ $v = old ]; then B=$OLD/bench/cellrt_bench; else B=$NEW/bench/cellrt_bench; fi
    for t in 1 2; do
      $B --scenes-dir ${SCENES:-../shared/scenes} --scenes sponza sibenik bunny teapot --configs embree:single bvh \
        --size 16x16 --repeats 1 --builds 5 --clock cpu --threads $t --json b_${v}_t${t}_$r.json > /dev/null
    done
  done
done
python3 table.py > table.md
