#!/usr/bin/env bash
# Downloads Debian's source package SOURCE at VERSION into DIR (no unpacking),
# from deb-src lines made out of the machine's own Debian sources, without
# touching the system's apt lists. Exit 1 with a reason on failure.
# Used by build_sundials.sh and ipopt_headers.sh.
set -uo pipefail
SOURCE=${1:?usage: debian_source.sh SOURCE VERSION DIR} VERSION=${2:?} DIR=${3:?}
src=/etc/apt/sources.list.d/debian.sources
[ -f "$src" ] || { echo "no $src" >&2; exit 1; }
mkdir -p "$DIR/.apt/lists/partial" "$DIR/.apt/cache/archives/partial"
sed 's/^Types: deb$/Types: deb-src/' "$src" > "$DIR/.apt/src.sources"
apt=(-o Dir::Etc::SourceList="$DIR/.apt/src.sources" -o Dir::Etc::SourceParts=/dev/null
     -o Dir::State::Lists="$DIR/.apt/lists" -o Dir::Cache="$DIR/.apt/cache")
apt-get "${apt[@]}" -qq update >/dev/null 2>&1 || { echo "apt-get update (deb-src) failed" >&2; exit 1; }
(cd "$DIR" && apt-get "${apt[@]}" -qq source --download-only "$SOURCE=$VERSION" >/dev/null 2>&1) ||
  { echo "apt-get source $SOURCE=$VERSION failed" >&2; exit 1; }
rm -rf "$DIR/.apt"
