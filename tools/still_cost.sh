#!/bin/sh
# The cost of a converged box still against one point frame, per scene
# (issue 35: a still costs at most 4x its point frame). Renders every scene
# in scenes/ at SIZE (default 128x128) twice, `--filter point` and the
# default box still, each as a whole process (start-up, warm shader cache)
# after one untimed warm-up run, and prints a Markdown table: scene, point s,
# box s, ratio, frames.
#   tools/still_cost.sh STRAHL [SIZE] [SCENE.json ...]
set -u
strahl=$1
size=${2:-128x128}
shift 2 2>/dev/null || shift $#
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -gt 0 ] || set -- "$root"/scenes/*.json
tmp=$(mktemp -d /tmp/still_cost.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }
echo "| scene | point s | box s | box / point | frames |"
echo "|---|---:|---:|---:|---:|"
for scene in "$@"; do
    name=$(basename "$scene" .json)
    if ! "$strahl" render "$scene" --size "$size" --filter point -o "$tmp/w.exr" >/dev/null 2>&1; then
        echo "| $name | refused | | | |"
        continue
    fi
    t0=$(now)
    "$strahl" render "$scene" --size "$size" --filter point -o "$tmp/p.exr" >/dev/null 2>&1
    t1=$(now)
    "$strahl" render "$scene" --size "$size" -o "$tmp/b.exr" >"$tmp/log" 2>&1
    t2=$(now)
    frames=$(sed -n 's/.*after \([0-9]*\) frame.*/\1/p' "$tmp/log" | tail -1)
    awk -v n="$name" -v a="$t0" -v b="$t1" -v c="$t2" -v f="${frames:-?}" \
        'BEGIN { p = b - a; q = c - b; printf "| %s | %.2f | %.2f | %.1f | %s |\n", n, p, q, q / p, f }'
done
