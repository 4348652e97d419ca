#!/bin/bash
# bench_main: main's build/bench/cellrt_bench (f0d8409); bench_new: this branch's (75894f0), both copied here before the runs.
# Two rounds, the binaries in turn: main new, then new main.
S=/work/shared/scenes
run() { # bin round
  for sc in teapot bunny sponza sibenik 'builtin:forest?tris=1000000'; do
    tag=$(echo "$sc" | sed 's/builtin:forest?tris=1000000/forest1M/')
    uptime >> load.txt
    ./bench_$1 --scenes-dir $S --scenes "$sc" --size 128x128 --repeats 3 --builds 3 --clock cpu --threads 1 --configs embree kd --json $1_${tag}_r$2.json > $1_${tag}_r$2.txt 2>&1
    echo "$1 $tag r$2 $(grep '^| kd' $1_${tag}_r$2.txt | cut -d'|' -f3,4)"
  done
}
run main 1; run new 1; run new 2; run main 2
