#!/bin/sh
# Whole frames, old binary against new (bench/frames_ab.sh): cellrt_scaling of 4bba393 (OLD_SCALING, built
# as run.sh says) and of this round's last commit. Run from the repository root.
bench/frames_ab.sh docs/figures/incoherent_round13 ${OLD_SCALING:-/tmp/old/build/bench/cellrt_scaling} \
  ${NEW_SCALING:-build/bench/cellrt_scaling}
