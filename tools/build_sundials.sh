#!/usr/bin/env bash
# Builds SUNDIALS (CVODES, ARKODE, KINSOL; static, -O2) from Debian's source
# package of the installed libsundials-dev into PREFIX.
#
# Why: Debian bookworm's libsundials 6.4.1 binaries are compiled without
# optimisation (their N_VLinearCombination_Serial keeps every loop variable on
# the stack), and on the drive's 9-18 states the integrators' own vector
# operations are most of the cost: the optimised build integrates faster (by
# how much: docs/performance.md, the SUNDIALS builds table). Same version, same sources, same API.
# If anything here fails, the build falls back to Debian's binaries (slower,
# same results) with a warning.
set -uo pipefail
PREFIX=${1:?usage: build_sundials.sh PREFIX}
[ -f "$PREFIX/lib/cmake/sundials/SUNDIALSConfig.cmake" ] && exit 0
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fallback() {
  echo "build_sundials: $1; using Debian's libsundials binaries" >&2
  [ -n "${2:-}" ] && [ -f "$2" ] && tail -n 5 "$2" >&2
  exit 0
}
version=$(dpkg-query -W -f='${Version}' libsundials-dev 2>/dev/null) || fallback "libsundials-dev is not installed"
# A private deb-src list from the machine's own Debian sources.
src=/etc/apt/sources.list.d/debian.sources
[ -f "$src" ] || fallback "no $src"
sed 's/^Types: deb$/Types: deb-src/' "$src" > "$WORK/src.sources"
apt=(-o Dir::Etc::SourceList="$WORK/src.sources" -o Dir::Etc::SourceParts=/dev/null
     -o Dir::State::Lists="$WORK/lists" -o Dir::Cache="$WORK/cache")
mkdir -p "$WORK/lists/partial" "$WORK/cache/archives/partial"
apt-get "${apt[@]}" -qq update >/dev/null 2>&1 || fallback "apt-get update (deb-src) failed"
(cd "$WORK" && apt-get "${apt[@]}" -qq source --download-only "sundials=$version" >/dev/null 2>&1) ||
  fallback "apt-get source sundials=$version failed"
tar -C "$WORK" -xJf "$WORK"/sundials_*.orig.tar.xz || fallback "cannot unpack the source"
srcdir=$(find "$WORK" -maxdepth 1 -type d -name 'sundials-*' | head -1)
echo "building SUNDIALS $version (CVODES, ARKODE, KINSOL; -O2, static) into $PREFIX"
cmake -S "$srcdir" -B "$WORK/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PREFIX" \
  -DBUILD_SHARED_LIBS=OFF -DBUILD_STATIC_LIBS=ON -DCMAKE_POSITION_INDEPENDENT_CODE=ON \
  -DBUILD_ARKODE=ON -DBUILD_CVODES=ON -DBUILD_KINSOL=ON -DBUILD_CVODE=OFF -DBUILD_IDA=OFF \
  -DBUILD_IDAS=OFF -DEXAMPLES_ENABLE_C=OFF -DEXAMPLES_INSTALL=OFF >"$WORK/cmake.log" 2>&1 ||
  fallback "cmake configure failed" "$WORK/cmake.log"
cmake --build "$WORK/build" -j "$(nproc)" >"$WORK/build.log" 2>&1 || fallback "compilation failed" "$WORK/build.log"
cmake --install "$WORK/build" >/dev/null 2>&1 || fallback "install failed"
