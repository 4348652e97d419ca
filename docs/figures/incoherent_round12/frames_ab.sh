#!/bin/sh
# Whole frames, old binary against new (bench/frames_ab.sh): cellrt_scaling of the commit before
# (OLD_SCALING, built as run.sh says) and of this one. Run from the repository root.
bench/frames_ab.sh docs/figures/incoherent_round12 ${OLD_SCALING:-/tmp/old/build/bench/cellrt_scaling} \
  ${NEW_SCALING:-build/bench/cellrt_scaling}
