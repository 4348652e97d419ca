#!/usr/bin/env bash
# 2 ranks on the 2-core VM, Sponza at 1920x1080, direct shading, written as PNG: cellrt-mpi of c0bff76
# (OLD, float pixels) against this change's (NEW, 8-bit pixels), with Open MPI's single-copy transport
# (this machine's default) and without it (OMPI_MCA_btl_vader_single_copy_mechanism=none, the case
# where pixels move only while both sides poll), beside the plain program on 2 threads; ROUNDS rounds,
# the configurations in turn. Every PNG is checked against the plain program's. Recorded: each run's
# --stats (render_seconds: rank 0's frame) and the whole command's wall time (wall.txt: loading,
# building, the frame and writing the PNG, whose 8-bit conversion the old program does on rank 0 after
# the frame and the new one on every rank within it).
# Usage: run.sh OLD_BUILD NEW_BUILD SCENES_DIR [ROUNDS]     (docs/DISTRIBUTED.md, "8-bit pixels")
set -euo pipefail
old="$1" new="$2" scenes="$3" rounds="${4:-7}" here="$(cd "$(dirname "$0")" && pwd)"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
rm -f "$here/wall.txt"
scene="$scenes/sponza/sponza.json"
for ((r = 1; r <= rounds; ++r)); do
  /usr/bin/time -f "plain r$r %e" -a -o "$here/wall.txt" "$new/cellrt" render "$scene" --size 1920x1080 \
    --threads 2 -o "$work/plain.png" --overwrite --stats "$here/plain.r$r.json" > /dev/null
  for copy in cma none; do
    for v in old new; do
      b="$old"; [ "$v" = new ] && b="$new"
      OMPI_MCA_btl_vader_single_copy_mechanism=$copy /usr/bin/time -f "$v.$copy r$r %e" -a -o "$here/wall.txt" \
        mpirun -np 2 "$b/cellrt-mpi" render "$scene" --size 1920x1080 -o "$work/$v.png" --overwrite \
        --stats "$here/$v.$copy.r$r.json" > /dev/null
      cmp -s "$work/$v.png" "$work/plain.png" || { echo "$v $copy: the frame differs" >&2; exit 1; }
    done
  done
done
