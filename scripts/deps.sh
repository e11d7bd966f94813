#!/usr/bin/env bash
# Install the Debian packages listed in scripts/deps.txt that are missing: one
# dpkg-query check, then one apt-get install of exactly the missing ones.
#   scripts/deps.sh      (make deps; needs root when something is missing)
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
here=$(cd "$(dirname "$0")" && pwd)
mapfile -t pkgs < <(grep -vE '^\s*(#|$)' "$here/deps.txt")
missing=()
for p in "${pkgs[@]}"; do
    st=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
    [ "$st" = "installed" ] || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "deps: all ${#pkgs[@]} Debian packages present"
    exit 0
fi
echo "deps: missing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
    echo "deps: error: installing packages needs root; run: sudo apt-get install --no-install-recommends ${missing[*]}" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
