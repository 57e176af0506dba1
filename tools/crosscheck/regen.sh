#!/usr/bin/env bash
# Regenerates the Cycles side of the cross-check suite (tests/data/crosscheck):
# the glTF test scenes (gltf_scene.glb; the user-made ones of
# make_user_scenes.py: ds_cornell, meshes, dense, fog_room, cloud_room,
# spot_room; the OpenVDB cloud cloud.vdb, written by the build's
# tests/toth/make_cloud_vdb), then for every case in cases.txt NAME.cycles.exr (mean
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
# The user-made scenes' glTF files, made when a case that uses one is asked for.
user=()
for g in ds_cornell meshes dense fog_room cloud_room spot_room; do
  for n in "$@"; do if grep -q "\"$g.glb\"" "$data/$n.json" 2>/dev/null; then user+=("$g"); break; fi; done
done
if [ $# -eq 0 ]; then user=(ds_cornell meshes dense fog_room cloud_room spot_room); fi
if [ $# -eq 0 ] || [[ " $* " == *" vdb_cloud "* ]]; then
  "${BUILD:-$root/build}/tests/toth/make_cloud_vdb" "$data/cloud.vdb"
fi
if [ ${#user[@]} -gt 0 ]; then
  blender -b --factory-startup --python "$py/make_user_scenes.py" -- "$data" "${user[@]}" 2>&1 |
    grep -E '^make_user_scenes|Error|error:' || true
fi
while read -r name kind spp filter; do
  case "$name" in ''|'#'*) continue ;; esac
  if [ $# -gt 0 ] && [[ " $* " != *" $name "* ]]; then continue; fi
  rm -f "$data/$name.cycles.exr" "$data/$name.cycles_se.exr" "$data/$name.cycles.json"
  blender_run "$py/cycles_render.py" -- "$data/$name.json" "$data/$name.cycles" \
    --spp "$spp" --seeds 1,2 --threads "$threads" --filter "${filter:-point}"
  [ -f "$data/$name.cycles.json" ] || { echo "regen: $name failed" >&2; exit 1; }
done < "$data/cases.txt"
