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
#
# Where the MPI programs were built (cellrt-mpi, cellrt_bench-mpi, cellrt_scaling-mpi), the bundle
# holds them and Open MPI's mpirun with what it loads at run time (docs/DISTRIBUTED.md): its launcher
# daemon, its components and PMIx's (plug-ins it opens by path), its help texts and its settings, each
# told to mpirun by the environment `run` sets (Open MPI's installation directories, OPAL_*, and PMIx's
# component path), so that
#
#   DIR/run mpirun --allow-run-as-root -np 16 cellrt-mpi render ...    # on one machine
#
# works where no Open MPI is installed. Where ssh is missing `run` makes mpirun launch on this machine
# only (plm isolated); several machines need ssh and the bundle at the same path on each.
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
mpi_programs=()
for p in "$build/cellrt-mpi" "$build/bench/cellrt_bench-mpi" "$build/bench/cellrt_scaling-mpi"; do
  if [[ -x "$p" ]]; then mpi_programs+=("$p"); fi
done
for p in "${programs[@]}"; do
  if [[ ! -x "$p" ]]; then
    echo "tools/bundle.sh: $p is missing: build first (cmake --build $build)" >&2
    exit 1
  fi
done

mkdir -p "$dir/bin" "$dir/lib"
cp "${programs[@]}" "$dir/bin/"
loaded=("${programs[@]}")
if ((${#mpi_programs[@]})); then
  # Open MPI's directories as it was built (Debian's split them: /usr/bin, /usr/lib/.../openmpi,
  # /usr/share/openmpi, /etc/openmpi, and PMIx under /usr/lib/.../pmix2).
  if ! paths="$(ompi_info --path all --parsable 2>/dev/null)"; then
    echo "tools/bundle.sh: the MPI programs are built but ompi_info is missing: install openmpi-bin" >&2
    exit 1
  fi
  path_of() { sed -n "s/^path:$1://p" <<<"$paths" | head -1; }
  pmix="$(ompi_info --config --parsable | grep -o "'--with-pmix=[^']*'" | sed "s/'--with-pmix=\(.*\)'/\1/")"
  mkdir -p "$dir/mpi/etc" "$dir/mpi/pmix"
  cp "${mpi_programs[@]}" "$dir/bin/"
  cp "$(path_of bindir)/orterun" "$dir/bin/mpirun"
  cp "$(path_of bindir)/orted" "$dir/bin/"
  cp -r "$(path_of pkglibdir)" "$dir/mpi/components"
  cp -r "$(path_of pkgdatadir)" "$dir/mpi/help"
  cp "$(path_of sysconfdir)/openmpi-mca-params.conf" "$dir/mpi/etc/"
  cp -r "$pmix/lib/pmix" "$dir/mpi/pmix/components"
  cp -r "$pmix/share/pmix" "$dir/mpi/pmix/help"
  loaded+=("${mpi_programs[@]}" "$dir/bin/mpirun" "$dir/bin/orted" "$dir"/mpi/components/*.so "$dir"/mpi/pmix/components/*.so)
fi
# Every library the programs load, but the C and C++ runtimes and the loader, which the other machine
# has (and which must match its kernel and loader rather than this machine's).
for p in "${loaded[@]}"; do ldd "$p"; done |
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
if [[ -d "$here/mpi" ]]; then
  # Open MPI and PMIx find their parts here (the ranks mpirun starts inherit this environment), and
  # mpirun starts the ranks, this bundle's programs, from its bin.
  export OPAL_PREFIX="$here/mpi" OPAL_EXEC_PREFIX="$here/mpi" OPAL_BINDIR="$here/bin" OPAL_LIBDIR="$here/lib" \
    OPAL_PKGLIBDIR="$here/mpi/components" OPAL_DATADIR="$here/mpi" OPAL_PKGDATADIR="$here/mpi/help" \
    OPAL_SYSCONFDIR="$here/mpi/etc" PMIX_MCA_mca_base_component_path="$here/mpi/pmix/components" \
    PMIX_PKGDATADIR="$here/mpi/pmix/help" PMIX_SYSCONFDIR="$here/mpi/pmix" PATH="$here/bin:$PATH"
  # Without ssh, mpirun's default launcher refuses to start even on one machine.
  if [[ ! -x "$(command -v ssh)" && ! -x "$(command -v rsh)" ]]; then export OMPI_MCA_plm="${OMPI_MCA_plm:-isolated}"; fi
fi
LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" exec "$here/bin/$program" "$@"
EOF
chmod +x "$dir/run"
echo "bundled $(ls "$dir/bin" | wc -l) programs and $(ls "$dir/lib" | wc -l) libraries in $dir ($(du -sh "$dir" | cut -f1))"
