#!/usr/bin/env bash
# Installs the Debian packages listed in packages.txt (the one list), as root or through sudo. Where
# every one is installed already it does nothing, so that a user without root can run tools/setup.sh
# on a machine set up for them.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t pkgs < <(grep -v '^[[:space:]]*#' packages.txt | grep -v '^[[:space:]]*$')
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps.sh: every package of packages.txt is installed"
  exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if ! command -v sudo > /dev/null; then
    echo "install-deps.sh: installing ${missing[*]} needs root or sudo" >&2
    exit 1
  fi
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
