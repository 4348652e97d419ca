#!/usr/bin/env bash
# Packs the built programs with the shared libraries they need beyond the C and C++ runtimes (oneTBB,
# Embree, stb, ...) into one folder, for a machine of the same architecture where the packages of
# packages.txt are not installed and cannot be (a cluster node, a lent benchmark machine):
#
#   tools/bundle.sh DIR [PROGRAM...] # after a build; DIR must not exist yet; PROGRAMs: more built programs
#   DIR/run cellrt_scaling --scenes-dir /path/to/scenes ...    # on the other machine
#
# DIR/run PROGRAM ARGS runs DIR/bin/PROGRAM with DIR/lib first on the library path. The programs are
# built for the build machine's baseline (the SIMD kernels are chosen at run time), so they run on any
# x86-64 machine with this glibc or a newer one.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELLRT_BUILD:-$root/build}"
if [[ $# -lt 1 ]]; then
  echo "usage: tools/bundle.sh DIR [PROGRAM...]   (the build is read from ${build}; CELLRT_BUILD names another)" >&2
  exit 2
fi
dir="$1"
if [[ -e "$dir" ]]; then
  echo "tools/bundle.sh: $dir exists; name a new folder" >&2
  exit 1
fi
programs=("$build/cellrt" "$build/bench/cellrt_scaling" "$build/bench/cellrt_bench" "${@:2}")
for p in "${programs[@]}"; do
  if [[ ! -x "$p" ]]; then
    echo "tools/bundle.sh: $p is missing: build first (cmake --build $build)" >&2
    exit 1
  fi
done

mkdir -p "$dir/bin" "$dir/lib"
cp "${programs[@]}" "$dir/bin/"
# Every library the programs load, but the C and C++ runtimes and the loader, which the other machine
# has (and which must match its kernel and loader rather than this machine's).
for p in "${programs[@]}"; do ldd "$p"; done |
  awk '$2 == "=>" && $3 ~ /^\// { print $3 }' | sort -u |
  grep -Ev '/(ld-linux[^/]*|libc|libm|libdl|librt|libpthread|libgcc_s|libstdc\+\+)\.so' |
  while read -r lib; do cp -L "$lib" "$dir/lib/"; done

cat > "$dir/run" <<'EOF'
#!/usr/bin/env bash
# Runs one of this bundle's programs with the bundle's libraries: run PROGRAM [ARGS...]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
if [[ $# -lt 1 || ! -x "$here/bin/$1" ]]; then
  echo "usage: $0 PROGRAM [ARGS...]; PROGRAM one of: $(ls "$here/bin" | tr '\n' ' ')" >&2
  exit 2
fi
program="$1"
shift
LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" exec "$here/bin/$program" "$@"
EOF
chmod +x "$dir/run"
echo "bundled $(ls "$dir/bin" | wc -l) programs and $(ls "$dir/lib" | wc -l) libraries in $dir ($(du -sh "$dir" | cut -f1))"
