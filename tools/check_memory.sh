#!/usr/bin/env bash
# Memory checks, by hand (not part of CI; valgrind with llvmpipe is slow):
#
#   tools/check_memory.sh [asan] [ctest] [valgrind]     (default: all three)
#
#   asan      debug preset (ASan + UBSan, build-debug/): every scene in
#             scenes/ through `strahl render --size 64x64` (with every module
#             the scene loads) and `strahl reference --spp 2 --size 64x64`
#   ctest     the debug preset's test suite (ctest --preset debug)
#   valgrind  memcheck --leak-check=full on `strahl render --size 32x32` and
#             `strahl reference --spp 1 --size 16x16` of every scene, from a
#             RelWithDebInfo build (build-memcheck/, tests off)
#
# Exits 1 if anything failed; the logs of failures are kept in the printed
# folder. The sanitizer environment is the debug test preset's
# (CMakePresets.json), repeated here for the commands run outside ctest:
# tests/sanitizers/keep_dri.c explains the preload, lsan.supp and
# valgrind.supp what they suppress and why.
set -uo pipefail
cd "$(dirname "$0")/.." || exit 1
root=$PWD
steps=("$@")
[ ${#steps[@]} -eq 0 ] && steps=(asan ctest valgrind)
logs=$(mktemp -d /tmp/strahl-memcheck.XXXXXX)
failed=0
export STRAHL_SHADER_PATH=$root/shaders LIBGL_ALWAYS_SOFTWARE=1

# Runs "$@" with its output in a log; prints one line per run.
run() {
  local name=$1
  shift
  local log=$logs/${name// /_}.log t0=$SECONDS rc=0
  "$@" >"$log" 2>&1 || rc=$?
  if [ $rc -eq 0 ]; then
    printf '  ok    %-52s %4ds\n' "$name" $((SECONDS - t0))
    rm -f "$log"
  else
    printf '  FAIL  %-52s %4ds  (exit %d, %s)\n' "$name" $((SECONDS - t0)) $rc "$log"
    failed=1
  fi
}

# Configures and builds; stops the script on failure.
build() {
  local name=$1
  shift
  if ! { "$@"; } >"$logs/build-$name.log" 2>&1; then
    echo "  FAIL  build $name ($logs/build-$name.log)"
    exit 1
  fi
}
# shellcheck disable=SC2317 # called through build()
build_debug() { cmake --preset debug && cmake --build --preset debug; }
# shellcheck disable=SC2317
build_memcheck() {
  cmake -S . -B build-memcheck -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBUILD_TESTING=OFF &&
    cmake --build build-memcheck
}

asan_env=(env LD_PRELOAD="$root/build-debug/lib/libst_keep_dri.so"
  ASAN_OPTIONS=verify_asan_link_order=0:intercept_tls_get_addr=0:detect_leaks=1:check_initialization_order=1:strict_string_checks=1
  LSAN_OPTIONS="suppressions=$root/tests/sanitizers/lsan.supp:print_suppressions=0"
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  STRAHL_MODULE_PATH="$root/build-debug/modules")

for step in "${steps[@]}"; do
  case $step in
  asan)
    echo "== ASan + UBSan: every scene (build-debug)"
    build debug build_debug
    for s in scenes/*.json; do
      n=$(basename "$s" .json)
      run "asan render $n" "${asan_env[@]}" build-debug/bin/strahl render "$s" --size 64x64 -o "$logs/$n.exr"
      run "asan reference $n" "${asan_env[@]}" build-debug/bin/strahl reference "$s" --spp 2 --size 64x64 \
        -o "$logs/$n-ref.exr"
    done
    rm -f "$logs"/*.exr
    ;;
  ctest)
    echo "== ctest --preset debug"
    build debug build_debug
    run "ctest --preset debug" ctest --preset debug
    ;;
  valgrind)
    echo "== valgrind memcheck: every scene (build-memcheck, RelWithDebInfo)"
    build memcheck build_memcheck
    # Mesa's disk shader cache compresses with zstd from its own thread and
    # memcheck flags its (Mesa's) uninitialised padding: off for this step.
    vg=(env STRAHL_MODULE_PATH="$root/build-memcheck/modules" MESA_SHADER_CACHE_DISABLE=true
      valgrind --error-exitcode=1 --leak-check=full "--errors-for-leak-kinds=definite,indirect,possible"
      --suppressions="$root/tests/sanitizers/valgrind.supp" --num-callers=40 --keep-debuginfo=yes)
    # MEMCHECK_SCENES="a b" limits the step to scenes/a.json, scenes/b.json.
    # One point-sampled frame: the box filter's accumulation runs the same
    # code per frame and is covered by the asan step; under memcheck each
    # llvmpipe frame costs minutes.
    scenes=(scenes/*.json)
    if [ -n "${MEMCHECK_SCENES:-}" ]; then
      read -ra scenes <<<"$MEMCHECK_SCENES"
      scenes=("${scenes[@]/#/scenes/}") && scenes=("${scenes[@]/%/.json}")
    fi
    for s in "${scenes[@]}"; do
      n=$(basename "$s" .json)
      run "valgrind render $n" "${vg[@]}" build-memcheck/bin/strahl render "$s" --size 32x32 --filter point \
        -o "$logs/$n.exr"
      run "valgrind reference $n" "${vg[@]}" build-memcheck/bin/strahl reference "$s" --spp 1 --size 16x16 \
        -o "$logs/$n-ref.exr"
    done
    rm -f "$logs"/*.exr
    ;;
  *)
    echo "unknown step '$step' (asan, ctest, valgrind)" >&2
    exit 2
    ;;
  esac
done
if [ $failed -eq 0 ]; then
  rmdir "$logs" 2>/dev/null
  echo "all memory checks passed"
else
  echo "memory checks FAILED; logs in $logs"
fi
exit $failed
