#!/usr/bin/env bash
# Installs the Debian packages strahl builds and runs with. Idempotent: packages
# already present are skipped by apt-get; runs as root or through sudo.
set -euo pipefail
pkgs=(build-essential cmake ninja-build pkg-config clang clang-format libclang-rt-dev git
      libglfw3-dev libepoxy-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libgbm1
      libcglm-dev libtinygltf-dev nlohmann-json3-dev libopenexr-dev libstb-dev libcjson-dev
      libembree-dev libopenvdb-dev libboost-dev gnuplot-nox xvfb xauth valgrind
      bsdutils python3-dev python3-numpy python3-venv python3-setuptools python3-pip)
# bsdutils: script(1), the pseudo-terminal of cli_first_hour's progress-line check;
# python3-*: the strahl Python module (python/), its tests and `pip install .`
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then echo "setup: all packages present"; exit 0; fi
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
