#!/bin/sh
# Builds on 2 threads (and 1): 08d9392's cellrt_bench (OLD: the layout on one thread after the build)
# against the parallel layout's (NEW), five rounds in turn, five builds a run (docs/BUILD_SPEED.md,
# "The layout on the build's threads"). Usage: run.sh OLD NEW SCENES_DIR
set -e
old=$1 new=$2 scenes=$3 here=$(dirname "$0")
for r in 1 2 3 4 5; do
  if [ $((r % 2)) = 1 ]; then order="old new"; else order="new old"; fi
  for v in $order; do
    bin=$old; [ $v = new ] && bin=$new
    for t in 1 2; do
      "$bin" --scenes-dir "$scenes" --scenes sponza sibenik bunny teapot 'builtin:forest?tris=1000000' \
        --size 16x16 --repeats 1 --builds 5 --threads $t --configs embree kd bih@split=sah \
        --json "$here/$v.t$t.r$r.json" > /dev/null
    done
  done
done
