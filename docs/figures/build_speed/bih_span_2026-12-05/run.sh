#!/bin/sh
# The BIH builds on 1 and 2 threads: c0bff76's cellrt_bench (OLD) against this change's (NEW), four
# rounds in turn (old new, new old, ...), five builds a run (docs/BUILD_SPEED.md, "Sixteen threads:
# the BIH's task tree"). Usage: run.sh OLD NEW SCENES_DIR
set -e
old=$1 new=$2 scenes=$3 here=$(dirname "$0")
for r in 1 2 3 4; do
  if [ $((r % 2)) = 1 ]; then order="old new"; else order="new old"; fi
  for v in $order; do
    bin=$old; [ $v = new ] && bin=$new
    for t in 1 2; do
      "$bin" --scenes-dir "$scenes" --scenes sponza sibenik bunny teapot 'builtin:forest?tris=1000000' \
        --size 16x16 --repeats 1 --builds 5 --threads $t --configs embree bih@split=sah bih \
        --json "$here/$v.t$t.r$r.json" > /dev/null
    done
  done
done
