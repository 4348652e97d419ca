#!/bin/sh
# The prototype's runs (wide_proto.cpp, INCOHERENT.md, seventeenth round): two levels at a time,
# pushed by branches (BRANCHY) or branch-free, and the interval traversal's copy with the near
# child's side read from dir_neg[] (DIRNEG) or the ray's origin read through the ray (RAYREF).
# Camera rays at 512 x 512, one thread, medians of seven runs. From the repository root, after
# the library is built; writes prototype.txt beside this script.
D=docs/figures/kd_octant
for v in "-DBRANCHY" "-DNONE" "-DBRANCHY -DDIRNEG" "-DBRANCHY -DRAYREF"; do
  g++ $v -std=c++20 -O3 -DNDEBUG -ffp-contract=off -Iinclude -Isrc $D/wide_proto.cpp build/libcellrt.a -ltbb -lpthread \
    -o /tmp/wide_proto || exit 1
  for s in bunny sponza; do
    echo "== $v $s"
    /tmp/wide_proto ../shared/scenes/$s/$s.json 512
  done
done > $D/prototype.txt
