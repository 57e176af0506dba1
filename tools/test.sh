#!/usr/bin/env bash
# Builds strahl (release preset) and runs every test. Installs the Debian
# packages it needs first, so it works on a fresh machine.
set -euo pipefail
cd "$(dirname "$0")/.."
./tools/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release "$@"
