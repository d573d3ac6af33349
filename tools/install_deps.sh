#!/usr/bin/env bash
# Installs the Debian packages given as arguments that are not installed yet.
# apt's output goes to a log file (DEPS_LOG, default build/deps.log); the
# screen gets one line per step, and the log's last lines if a step fails.
set -euo pipefail
missing=()
for p in "$@"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
log=${DEPS_LOG:-build/deps.log}
mkdir -p "$(dirname "$log")"
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
step() {
  echo "deps: $1 (log: $log)"
  shift
  if ! "$@" >>"$log" 2>&1; then
    echo "deps: failed; the log's last lines:" >&2
    tail -n 20 "$log" >&2
    exit 1
  fi
}
step "updating the package lists" $SUDO apt-get update -qq
step "installing ${#missing[@]} Debian packages: ${missing[*]}" \
  env DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
