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
why=$(bash "$(dirname "$0")/debian_source.sh" sundials "$version" "$WORK" 2>&1) || fallback "$why"
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
