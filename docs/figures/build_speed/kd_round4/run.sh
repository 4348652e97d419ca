#!/bin/sh
# The kd-tree builder's fourth round (docs/BUILD_SPEED.md), measured. OLD and NEW: two checkouts.
# 1. Tree bytes and instructions: docs/figures/tree_hash.cpp linked once with each checkout's kd_build.cpp
#      g++ -I include -I src -O3 -DNDEBUG -ffp-contract=off -std=c++20 docs/figures/tree_hash.cpp src/kdtree/kd_build.cpp \
#          build/libcellrt.a -ltbb -lembree3 -o tree_hash
#      ./tree_hash kd SCENE REPEATS THREADS [CLIP_RATIO MAX_BAD_REFINES]      # prints nodes, hash, best ms
#      valgrind --tool=callgrind --callgrind-out-file=/dev/null --toggle-collect='cellrt::detail::build_*' ./tree_hash kd SCENE 1 1
# 2. float_below/above against their earlier definitions: g++ -O2 -std=c++20 -I src outward_check.cpp && ./a.out
# 3. The events' sort alone, rank against network, on Sponza's list sizes: g++ -O3 -std=c++20 sort_bench.cpp && ./a.out
# 4. Build time beside Embree's, the binaries in turn, three rounds (kd_old_N.json, kd_new_N.json):
set -e
for r in 1 2 3; do
  for v in old new; do
    if [ $v = old ]; then B=$OLD/bench/cellrt_bench; else B=$NEW/bench/cellrt_bench; fi
    $B --scenes-dir ../shared/scenes --scenes teapot bunny sponza sibenik 'builtin:forest?tris=200000' \
      --configs embree:single kd:branched --size 16x16 --repeats 1 --builds 5 --clock cpu --threads 1 --json kd_${v}_$r.json
  done
done
