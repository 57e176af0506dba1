#!/usr/bin/env bash
# Regenerates the Cycles side of the cross-check suite (tests/data/crosscheck):
# the glTF test scene, then for every case in cases.txt NAME.cycles.exr (mean
# of seeds 1 and 2), NAME.cycles_se.exr (per-pixel standard error of that
# mean) and NAME.cycles.json (settings, render times, noise summary).
# Needs Blender 3.4 and numpy (apt-get install blender python3-numpy); CI
# never runs this. Usage: tools/crosscheck/regen.sh [CASE...] (default: all)
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
data="$root/tests/data/crosscheck"
py="$root/tools/crosscheck"
threads="${THREADS:-2}"
blender_run() { blender -b --factory-startup --python "$@" 2>&1 | grep -E '^cycles_render|Error|error:' || true; }

if [ $# -eq 0 ] || [[ " $* " == *" gltf_scene "* ]]; then
  blender_run "$py/make_gltf_scene.py" -- "$data/gltf_scene.glb"
fi
while read -r name kind spp; do
  case "$name" in ''|'#'*) continue ;; esac
  if [ $# -gt 0 ] && [[ " $* " != *" $name "* ]]; then continue; fi
  rm -f "$data/$name.cycles.exr" "$data/$name.cycles_se.exr" "$data/$name.cycles.json"
  blender_run "$py/cycles_render.py" -- "$data/$name.json" "$data/$name.cycles" \
    --spp "$spp" --seeds 1,2 --threads "$threads"
  [ -f "$data/$name.cycles.json" ] || { echo "regen: $name failed" >&2; exit 1; }
done < "$data/cases.txt"
