#!/usr/bin/env bash
# Checks the formatting, builds strahl (release preset) and runs every test, then the fuzz smoke
# tests: the fuzz preset (clang, ASan + UBSan, libFuzzer) builds only the
# fuzz targets and runs each for ~20 s from its seeds (ctest label "fuzz").
# STRAHL_SKIP_FUZZ=1 skips that part. Arguments go to the release ctest.
# Installs the Debian packages it needs first, so it works on a fresh machine.
set -euo pipefail
cd "$(dirname "$0")/.."
./tools/setup.sh
# Style: every C/C++ file as .clang-format says (clang-format -i to fix).
git ls-files '*.c' '*.h' '*.cpp' | xargs clang-format --dry-run --Werror
# No function over 80 lines in the framework, the plugins, the tools and the Python module.
python3 tools/fn_lengths.py framework modules tools python
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release "$@"
if [ "${STRAHL_SKIP_FUZZ:-0}" != 1 ]; then
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz
  ctest --preset fuzz
fi
