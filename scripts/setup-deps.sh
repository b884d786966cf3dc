#!/usr/bin/env bash
# Installs the Debian packages fracflow builds and runs with. Idempotent: only
# missing packages are installed. Needs root for apt-get (prints what to do otherwise).
set -euo pipefail
PKGS=(g++ cmake make libeigen3-dev libtomlplusplus-dev libcli11-dev libfmt-dev
      libgtest-dev googletest nlohmann-json3-dev libomp-dev clang libclang-rt-14-dev
      libcgal-dev libgmp-dev libmpfr-dev
      python3 python3-matplotlib python3-numpy)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "fracflow: installing missing Debian packages: ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO=sudo; else
    echo "fracflow: need root to install: apt-get install ${missing[*]}" >&2
    echo "          run this script as root, or install those packages and retry." >&2
    exit 1
  fi
else SUDO=""; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
