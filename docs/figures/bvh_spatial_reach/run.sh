#!/bin/sh
# The BVH's spatial-split reach rule (docs/BVH.md, "Build"), measured. OLD and NEW are two checkouts'
# build folders; docs/figures/tree_hash.cpp is linked once with each one's src/bvh/bvh_build.cpp.
# 1. Instructions of the build, tree hash, SAH cost, references (callgrind.txt):
#    g++ -I include -I src -O3 -DNDEBUG -ffp-contract=off -std=c++20 docs/figures/tree_hash.cpp src/bvh/bvh_build.cpp \
#        build/libcellrt.a -ltbb -lembree3 -o tree_hash
#    valgrind --tool=callgrind --callgrind-out-file=/dev/null --toggle-collect='cellrt::detail::build_bvh*' \
#        ./tree_hash bvh SCENE 1 1
# 2. Build time beside Embree's, the binaries in turn, three rounds (b_old_N.json, b_new_N.json):
set -e
for r in 1 2 3; do
  for v in old new; do
    if [ $v = old ]; then B=$OLD/bench/cellrt_bench; else B=$NEW/bench/cellrt_bench; fi
    $B --scenes-dir ../shared/scenes --scenes bunny teapot sponza --configs embree:single bvh --size 16x16 \
      --repeats 1 --builds 5 --clock cpu --threads 1 --json b_${v}_$r.json
  done
done
