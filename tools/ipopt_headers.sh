#!/usr/bin/env bash
# Puts Ipopt's internal headers (IpAlgBuilder.hpp, IpTSymLinearSolver.hpp ...)
# into DIR: Debian's coinor-libipopt-dev installs only the application-level
# ones, and mechopt's dense KKT solver plugs into Ipopt below that level
# (libopt/src/drivers/ipopt_dense_solver.cpp). They come from Debian's source package
# of the installed version, so they declare exactly the library's classes;
# only headers the -dev package lacks are copied (its own, configured ones
# stay in charge). Debian's patches change no header but in comments.
set -uo pipefail
DIR=${1:?usage: ipopt_headers.sh DIR}
[ -f "$DIR/IpTSymLinearSolver.hpp" ] && exit 0
fail() { echo "ipopt_headers: $1 (mechopt needs Ipopt's internal headers: docs/drivers.md)" >&2; exit 1; }
read -r source version < <(dpkg-query -W -f='${source:Package} ${source:Version}\n' coinor-libipopt-dev 2>/dev/null) ||
  fail "coinor-libipopt-dev is not installed"
installed=$(pkg-config --variable=includedir ipopt)
[ -f "$installed/IpIpoptApplication.hpp" ] || installed=/usr/include/coin
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
why=$(bash "$(dirname "$0")/debian_source.sh" "$source" "$version" "$WORK" 2>&1) || fail "$why"
tar -C "$WORK" -xzf "$WORK"/"${source}"_*.orig.tar.gz || fail "cannot unpack the source"
src=$(find "$WORK" -maxdepth 3 -type d -path '*/Ipopt/src' | head -1)
[ -n "$src" ] || fail "no Ipopt/src in the source package"
mkdir -p "$DIR.tmp"
find "$src" -name '*.hpp' -not -path '*/Apps/*' | while read -r f; do
  [ -f "$installed/$(basename "$f")" ] || cp "$f" "$DIR.tmp/"
done
[ -f "$DIR.tmp/IpTSymLinearSolver.hpp" ] || fail "IpTSymLinearSolver.hpp is not in the source"
rm -rf "$DIR" && mv "$DIR.tmp" "$DIR"
echo "ipopt_headers: $(ls "$DIR" | wc -l) internal headers of Ipopt $version in $DIR"
