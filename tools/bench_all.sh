#!/usr/bin/env bash
# Regenerates every benchmark table and plot of docs/benchmarks.md from the
# scenes in scenes/: references with `strahl reference`, sweeps with
# `strahl bench` (CSV + log-log plot per technique), tables from the CSVs.
# Takes about half an hour on 2 cores with llvmpipe. Not part of CI.
#   GODRAY_SIZE (512x512), GI_SIZE (128x128), FRAMES (5), REF_SPP (16),
#   GI_REF_SPP (16384: the Cornell light sits 10 cm under the ceiling, and the
#   reference's bounce needs that many samples for its noise to stay well
#   below the errors measured), ONLY (godrays, gi, or plots: run one part)
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/strahl
OUT=docs/bench
GODRAY_SIZE=${GODRAY_SIZE:-512x512}
GI_SIZE=${GI_SIZE:-128x128}
GI_REF_SPP=${GI_REF_SPP:-16384}
ONLY=${ONLY:-all}
FRAMES=${FRAMES:-5}
REF_SPP=${REF_SPP:-16}
[ -x "$S" ] || { cmake --preset release >/dev/null && cmake --build --preset release; }
mkdir -p "$OUT"
log() { echo "bench_all: $*" >&2; }

# Reference: the full physical model without bounces for the god-ray scenes
# (none of the volumetric plugins adds indirect light), with the atlas_gi
# settings for the GI scenes.
ref() { # scene size out [reference options]
    local scene=$1 size=$2 out=$3; shift 3
    [ -f "$out" ] && [ "$out" -nt "$scene" ] && return 0
    log "reference $scene -> $out"
    "$S" reference "$scene" -o "$out" --size "$size" "$@"
}

bench() { # scene size ref csv metric sweeps...
    local scene=$1 size=$2 reffile=$3 csv=$4 metric=$5; shift 5
    log "bench $scene $*"
    "$S" bench "$scene" --reference "$reffile" --size "$size" --frames "$FRAMES" --warmup 1 \
        --metric "$metric" --csv "$csv" --append "$@" > "${csv%.csv}.log"
}

# ---- god rays ---------------------------------------------------------------
if [ "$ONLY" = all ] || [ "$ONLY" = godrays ]; then
rm -f "$OUT"/toth.csv "$OUT"/mitchell.csv "$OUT"/sousa.csv
for s in window colonnade hidden_hole light_front; do
    ref scenes/godrays_$s.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" --spp "$REF_SPP" --bounces 0
done
for s in window colonnade; do
    bench scenes/godrays_$s.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/toth.csv" rmse \
        --sweep toth.samples=8,16,32,64,128,256 --sweep toth.interleave=1,2 --sweep toth.resolution=full,half
    bench scenes/godrays_${s}_mitchell.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/mitchell.csv" scaled_rmse \
        --sweep mitchell.n=16,32,64,128
    bench scenes/godrays_${s}_sousa.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/sousa.csv" scaled_rmse \
        --sweep sousa.taps=4,6,8,10,12
done
for s in hidden_hole light_front; do
    bench scenes/godrays_$s.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/toth.csv" rmse \
        --sweep toth.samples=16,64,128
    bench scenes/godrays_${s}_mitchell.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/mitchell.csv" scaled_rmse \
        --sweep mitchell.n=64
    bench scenes/godrays_${s}_sousa.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/sousa.csv" scaled_rmse \
        --sweep sousa.taps=6
done

fi

# ---- atlas GI (the thesis' Table 1) -------------------------------------------
if [ "$ONLY" = all ] || [ "$ONLY" = gi ]; then
rm -f "$OUT"/atlas_gi.csv
for s in gi_cornell gi_dense; do
    ref scenes/$s.json "$GI_SIZE" "$OUT/ref_${s}_area.exr" --spp "$GI_REF_SPP" --bounces 1 --bounce-visibility off
    ref scenes/$s.json "$GI_SIZE" "$OUT/ref_${s}_vis.exr" --spp "$GI_REF_SPP" --bounces 1 --bounce-visibility on
    bench scenes/$s.json "$GI_SIZE" "$OUT/ref_${s}_area.exr" "$OUT/atlas_gi.csv" rmse \
        --set atlas_gi.mode=gather --set atlas_gi.progressive=false \
        --set atlas_gi.visibility=false --set atlas_gi.sampling=uniform \
        --sweep atlas_gi.samples=10,50,100,200,400 --sweep atlas_gi.atlas_size=512,1024 \
        --sweep atlas_gi.estimator=area,thesis
    bench scenes/$s.json "$GI_SIZE" "$OUT/ref_${s}_vis.exr" "$OUT/atlas_gi.csv" rmse \
        --set atlas_gi.mode=gather --set atlas_gi.progressive=false --set atlas_gi.visibility=true \
        --set atlas_gi.sampling=uniform --sweep atlas_gi.samples=10,100,400 --sweep atlas_gi.atlas_size=512
    # The precomputed transfer (the default), per relight (--mode recompute).
    bench scenes/$s.json "$GI_SIZE" "$OUT/ref_${s}_vis.exr" "$OUT/atlas_gi.csv" rmse \
        --set atlas_gi.mode=transfer --sweep atlas_gi.atlas_size=512,1024
done

fi

# ---- plots and tables -------------------------------------------------------
for m in toth mitchell sousa atlas_gi; do
    csv=$OUT/$m.csv
    [ -f "$csv" ] || continue
    metric=$(head -1 "$csv" | cut -d, -f9 | sed 's/^error_//')
    # One plot per scene: split the CSV by its first column.
    for scene in $(tail -n +2 "$csv" | cut -d, -f1 | sort -u); do
        name=$(basename "$scene" .json)
        part=$OUT/${m}_${name}.csv
        { head -1 "$csv"; grep "^$scene," "$csv"; } > "$part"
        gnuplot -e "set terminal pngcairo size 900,600; set output '$OUT/${m}_${name}.png'; \
            set datafile separator ','; set logscale xy; set grid; set key outside right; \
            set title '$m on $name' noenhanced; set xlabel 'median frame time [ms]'; set ylabel '$metric vs reference'; \
            curves = system(\"tail -n +2 $part | cut -d, -f3 | sort -u | tr ' ' '_' | tr '\\\\n' ' '\"); \
            plot for [c in curves] '< tail -n +2 $part | tr \" \" \"_\"' using ((strcol(3) eq c) ? \$6 : 1/0):((strcol(3) eq c) ? \$9 : 1/0) with linespoints title c noenhanced"
        rm -f "$part"
    done
done

table() { # csv -> markdown rows: scene, setting, frame ms, module gpu ms, error
    echo "| scene | setting | frame ms (median) | module GPU ms (median) | error |"
    echo "|---|---|---:|---:|---:|"
    tail -n +2 "$1" | awk -F, '{ n = split($1, p, "/"); printf "| %s | %s | %.1f | %.1f | %.4g |\n", p[n], $2, $6, $7, $9 }'
}
{
    echo "<!-- generated by tools/bench_all.sh; edit the script, not this block -->"
    for m in toth mitchell sousa atlas_gi; do
        [ -f "$OUT/$m.csv" ] || continue
        echo
        echo "### $m ($(head -1 "$OUT/$m.csv" | cut -d, -f9 | sed 's/^error_//'))"
        echo
        table "$OUT/$m.csv"
        echo
        for p in "$OUT"/${m}_*.png; do [ -f "$p" ] && echo "![$(basename "$p" .png)](bench/$(basename "$p"))"; done
    done
} > "$OUT/tables.md"
log "done: $OUT/tables.md and plots"

# Splice the tables into docs/benchmarks.md between its markers.
awk -v tables="$OUT/tables.md" '
    /<!-- BEGIN GENERATED -->/ { print; while ((getline line < tables) > 0) print line; skip = 1; next }
    /<!-- END GENERATED -->/ { skip = 0 }
    !skip { print }' docs/benchmarks.md > docs/benchmarks.md.tmp && mv docs/benchmarks.md.tmp docs/benchmarks.md
log "docs/benchmarks.md updated"
