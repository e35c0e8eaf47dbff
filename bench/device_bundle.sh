#!/usr/bin/env bash
# Gathers what bench/scaling_device.sh needs on a bare x86-64 Linux machine that has none of our
# Debian packages and no network (the device machine of issue #30) into one folder: the prebuilt
# programs, every shared library they load that is not the C/C++ runtime, and a relocatable copy of
# Debian's Open MPI (mpirun, its components, PMIx and their libraries, help texts). On the machine,
# `source DIR/env.sh` points PATH, LD_LIBRARY_PATH, Open MPI and PMIx at the folder and sets
# MASA_BUILD_DIR; tests/mpi/device_bundle.sh trains with 2 ranks from it with the system's
# copies hidden.
#   bench/device_bundle.sh [--build BUILD] [--out DIR] [--programs "PATH ..."]   (default: build, .device,
#                          the programs of scaling_device.sh and masa_config, which the launchers
#                          size the batch with; paths inside BUILD)
set -euo pipefail
cd "$(dirname "$0")/.."
build=build out=.device
programs=(learner/masa_learner actors/masa_actor tools/masa_config bench/bench_learner_ranks bench/bench_efficiency_bound)
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --programs) read -r -a programs <<< "$2"; shift 2 ;;
    *) echo "device_bundle.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
for p in "${programs[@]}"; do
  [ -x "$build/$p" ] || { echo "device_bundle.sh: $build/$p is missing (scripts/build.sh, bench/build_benchmarks.sh)" >&2; exit 2; }
done
ompi=/usr/lib/x86_64-linux-gnu/openmpi pmix=/usr/lib/x86_64-linux-gnu/pmix2
[ -d "$ompi/lib/openmpi3" ] && [ -d "$pmix/lib/pmix" ] && command -v orterun > /dev/null ||
  { echo "device_bundle.sh: Debian's Open MPI is not installed (scripts/install_deps.sh)" >&2; exit 2; }

rm -rf "$out"
mkdir -p "$out/build" "$out/lib" "$out/bin" "$out/ompi/lib" "$out/pmix/lib" "$out/share" "$out/etc"
for p in "${programs[@]}"; do
  mkdir -p "$out/build/$(dirname "$p")"
  cp "$build/$p" "$out/build/$p"
  strip --strip-unneeded "$out/build/$p"
done
echo "$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- . 2> /dev/null || echo '+changes') ($build)" > "$out/COMMIT"
touch "$out/build/PREBUILT"  # bench/build_benchmarks.sh builds nothing in a prebuilt copy
cp "$(command -v orterun)" "$out/bin/orterun"
ln -s orterun "$out/bin/mpirun"
cp -a "$ompi/lib/openmpi3" "$out/ompi/lib/"
cp -a "$ompi"/lib/lib*.so* "$out/ompi/lib/"
find "$out/ompi/lib" -maxdepth 1 -xtype l -delete  # links to the libraries beside ours: copied below
cp -a "$pmix/lib/pmix" "$pmix"/lib/libpmix.so* "$out/pmix/lib/"
cp -a /usr/share/openmpi "$out/share/openmpi"
[ -d "$pmix/share/pmix" ] && cp -a "$pmix/share/pmix" "$out/share/pmix"
cp -a /etc/openmpi "$out/etc/openmpi"

# Every library those load, found by the loader here, except the C and C++ runtime that any Linux
# has (a newer one there serves our programs; an older one of ours could break its programs).
runtime='^(linux-vdso|ld-linux|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s)\.so'
mapfile -t objects < <(find "$out/build" "$out/bin" "$out/ompi" "$out/pmix" -type f \( -perm -u+x -o -name '*.so*' \))
ldd "${objects[@]}" 2> /dev/null | awk '$2 == "=>" && $3 ~ /^\// { print $1, $3 }' | sort -u |
  while read -r name path; do
    [[ $name =~ $runtime ]] && continue
    [ -e "$out/ompi/lib/$name" ] || [ -e "$out/pmix/lib/$name" ] || [ -e "$out/lib/$name" ] || cp -L "$path" "$out/lib/$name"
  done
missing=$(LD_LIBRARY_PATH="$out/lib:$out/ompi/lib:$out/pmix/lib" ldd "${objects[@]}" 2> /dev/null | grep -c 'not found' || true)
[ "$missing" = 0 ] || { echo "device_bundle.sh: $missing libraries not found" >&2; exit 1; }
strip --strip-unneeded "$out"/lib/*.so* "$out"/ompi/lib/*.so* "$out"/ompi/lib/openmpi3/*.so "$out"/pmix/lib/*.so* \
  "$out"/pmix/lib/pmix/*.so 2> /dev/null || true

cat > "$out/env.sh" << 'EOF'
# Sourced on the bare machine: our programs, libraries and Open MPI from this folder.
d=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export PATH="$d/bin:$PATH" LD_LIBRARY_PATH="$d/lib:$d/ompi/lib:$d/pmix/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export MASA_BUILD_DIR="$d/build" MASA_MPIRUN="$d/bin/mpirun"
# Open MPI and PMIx find their components, help texts and settings under these (both look the
# variables up before their configured paths).
export OPAL_PREFIX="$d" OPAL_EXEC_PREFIX="$d" OPAL_BINDIR="$d/bin" OPAL_LIBDIR="$d/ompi/lib" \
  OPAL_PKGLIBDIR="$d/ompi/lib/openmpi3" OPAL_DATADIR="$d/share" OPAL_DATAROOTDIR="$d/share" \
  OPAL_PKGDATADIR="$d/share/openmpi" OPAL_SYSCONFDIR="$d/etc/openmpi"
export PMIX_INSTALL_PREFIX="$d/pmix" PMIX_MCA_mca_base_component_path="$d/pmix/lib/pmix"
export OMPI_MCA_mca_base_component_path="$d/ompi/lib/openmpi3"
EOF
echo "device_bundle.sh: $(du -sh "$out" | cut -f1) in $out ($(ls "$out/lib" | wc -l) libraries); on the machine: source $out/env.sh"
