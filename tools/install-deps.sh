#!/usr/bin/env bash
# Installs the Debian packages listed in packages.txt (the one list), as root or through sudo.
set -euo pipefail
cd "$(dirname "$0")/.."
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
mapfile -t pkgs < <(grep -v '^[[:space:]]*#' packages.txt | grep -v '^[[:space:]]*$')
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${pkgs[@]}"
