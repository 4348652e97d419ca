#!/bin/sh
# Where issue 18's targets stand after the thirteenth round: bench/incoherent_state.sh over this round's
# binary. Its `bvh` column was the one-ray kernel, named `bvh:wide` since `paired` became bvh's default.
bench/incoherent_state.sh docs/figures/incoherent_round13 ${NEW:-build/bench/cellrt_bench}
