#!/bin/sh
# "The refactor changes no image": renders every scene in scenes/ (plus a few
# variants that reach code the scenes do not: ssgi, two lights for sousa and
# mitchell) at a small fixed size and frame count with two strahl builds, and
# compares each pair with `strahl compare`: every max_abs must be 0.
#
#   tools/check_images_unchanged.sh BEFORE_STRAHL AFTER_STRAHL [OUTDIR]
#
# BEFORE_STRAHL / AFTER_STRAHL are strahl binaries (e.g. build/tools/strahl of
# main and of the branch). Scenes that the GPU path refuses on purpose (a
# varying medium.density exits 2) are listed as skipped when both builds
# refuse them. Exit 0 when every pair is identical, 1 otherwise.
# AFTER_STRAHL "none" only renders the BEFORE images into OUTDIR; a later run
# with the same OUTDIR and ST_CHECK_REUSE=1 keeps them and renders AFTER only
# (e.g. before/after a rebuild of one tree).
set -u
before=$1
after=$2
out=${3:-$(mktemp -d /tmp/strahl_images.XXXXXX)}
root=$(cd "$(dirname "$0")/.." && pwd)
size=${ST_CHECK_SIZE:-96x96}
frames=${ST_CHECK_FRAMES:-4}
mkdir -p "$out/scenes" "$out/before" "$out/after"

# The scenes, the Cycles cross-check cases (tests/data/crosscheck, as
# xc_<case>) and the variants (absolute asset paths so they render from $out).
python3 - "$root/scenes" "$out/scenes" "$root/tests/data/crosscheck" <<'EOF'
import json, os, sys
src, dst, xc = sys.argv[1], sys.argv[2], sys.argv[3]
def fix(node, base=src):
    if isinstance(node, dict):
        for k, v in node.items():
            if k in ("gltf", "vdb", "file") and isinstance(v, str) and not os.path.isabs(v):
                node[k] = os.path.join(base, v)
            else:
                fix(v, base)
    elif isinstance(node, list):
        for v in node:
            fix(v, base)
def write(name, s):
    with open(os.path.join(dst, name + ".json"), "w") as f:
        json.dump(s, f, indent=1)
for n in sorted(os.listdir(src)):
    if not n.endswith(".json"):
        continue
    s = json.load(open(os.path.join(src, n)))
    fix(s)
    write(n[:-5], s)
for n in sorted(os.listdir(xc)):
    if n.endswith(".json") and not n.endswith(".cycles.json"):
        s = json.load(open(os.path.join(xc, n)))
        fix(s, xc)
        write("xc_" + n[:-5], s)
base = json.load(open(os.path.join(src, "cornell.json")))
ssgi = dict(base, modules=[{"name": "ssgi", "params": {"samples": 64}}])
write("variant_ssgi", ssgi)
write("variant_ssgi_thesis", dict(base, modules=[{"name": "ssgi", "params": {"samples": 32, "estimator": "thesis", "display": "indirect"}}]))
for m in ("sousa", "mitchell"):
    s = json.load(open(os.path.join(src, "godrays_window_%s.json" % m)))
    fix(s)
    l2 = dict(s["lights"][0])
    l2["position"] = [p + d for p, d in zip(l2["position"], (0.7, -0.2, 0.4))]
    s["lights"] = s["lights"] + [l2]
    write("variant_%s_two_lights" % m, s)
    s = json.load(open(os.path.join(src, "godrays_window_%s.json" % m)))
    fix(s)
    for mod in s["modules"]:
        if mod["name"] == m:
            mod.setdefault("params", {})["resolution"] = 0.5
    write("variant_%s_half" % m, s)
EOF

fail=0
same=0
skipped=0
for scene in "$out"/scenes/*.json; do
    name=$(basename "$scene" .json)
    # The copies name their assets by absolute path (outside their folder).
    args="render $scene --size $size --frames $frames --allow-outside-assets"
    if [ "${ST_CHECK_REUSE:-0}" = 1 ] && [ -f "$out/before/$name.rc" ]; then
        rb=$(cat "$out/before/$name.rc")
    else
        "$before" $args -o "$out/before/$name.exr" >"$out/before/$name.log" 2>&1
        rb=$?
        echo $rb >"$out/before/$name.rc"
    fi
    if [ "$after" = none ]; then
        echo "rendered $name (exit $rb)"
        continue
    fi
    "$after" $args -o "$out/after/$name.exr" >"$out/after/$name.log" 2>&1
    ra=$?
    if [ $rb -ne 0 ] || [ $ra -ne 0 ]; then
        if [ $rb -eq $ra ]; then
            echo "skipped  $name (both exit $rb: $(head -c 120 "$out/after/$name.log" | tr '\n' ' '))"
            skipped=$((skipped + 1))
        else
            echo "DIFFERS  $name (exit before $rb, after $ra)"
            fail=1
        fi
        continue
    fi
    m=$("$after" compare "$out/before/$name.exr" "$out/after/$name.exr" --json |
        python3 -c 'import json,sys; print(max(json.load(sys.stdin)["max_abs"].values()))')
    if [ "$m" = "0" ]; then
        echo "same     $name (max_abs 0)"
        same=$((same + 1))
    else
        echo "DIFFERS  $name (max_abs $m)"
        fail=1
    fi
done
echo "$same identical, $skipped skipped (refused by both), images in $out"
exit $fail
