#!/usr/bin/env bash
# Regenerates every benchmark table and plot of docs/benchmarks.md from the
# scenes in scenes/: references with `strahl reference`, sweeps with
# `strahl bench` (CSV + log-log plot per technique), tables from the CSVs.
# Takes about half an hour on 2 cores with llvmpipe. Not part of CI.
#   GODRAY_SIZE (512x512), GI_SIZE (128x128), FRAMES (5), REF_SPP (16),
#   GI_REF_SPP (16384: the Cornell light sits 10 cm under the ceiling, and the
#   reference's bounce needs that many samples for its noise to stay well
#   below the errors measured), ONLY (godrays, toth, gi, or plots: run one
#   part; godrays is toth, mitchell and sousa), TOTH_MODE (steady),
#   LIGHT_VIEW_SIZE (384x256)
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

# ---- toth: equi-angular against the brute-force march ------------------------
# Reference: a 1024-step full-resolution uniform march of the same model,
# rendered by strahl itself (noise-free). One bench run per scene holds the
# brute force (uniform, full resolution, 128 steps, no interleave) and the
# equi-angular method side by side. --mode steady (TOTH_MODE): the scene is
# static, the shadow map is cached, the per-frame cost is the regular pass plus
# toth's passes. toth_passes.txt has every pass's GPU time (shadow map and
# regular pass included) for the defaults and the brute force.
TOTH_MODE=${TOTH_MODE:-steady}
LIGHT_VIEW_SIZE=${LIGHT_VIEW_SIZE:-384x256}
if [ "$ONLY" = all ] || [ "$ONLY" = godrays ] || [ "$ONLY" = toth ]; then
rm -f "$OUT"/toth.csv "$OUT"/toth_passes.txt "$OUT"/toth_recompute.csv
BRUTE="--set toth.sampling=uniform --set toth.samples=128 --set toth.interleave=1 --set toth.resolution=full"
for s in window colonnade hidden_hole light_front light_view; do
    scene=scenes/godrays_$s.json size=$GODRAY_SIZE
    [ "$s" = light_view ] && size=$LIGHT_VIEW_SIZE
    log "toth reference $scene (1024 uniform steps)"
    "$S" render "$scene" -o "$OUT/toth_ref_$s.exr" --size "$size" --set toth.sampling=uniform \
        --set toth.samples=1024 --set toth.interleave=1 --set toth.resolution=full
    bench "$scene" "$size" "$OUT/toth_ref_$s.exr" "$OUT/toth.csv" rmse --mode "$TOTH_MODE" \
        --set toth.interleave=1 --sweep toth.samples=8,16,32,64,128 \
        --sweep toth.sampling=uniform,equiangular --sweep toth.resolution=full,quarter
    for cfg in defaults brute; do
        # shellcheck disable=SC2086
        { echo "== $s $cfg"; "$S" render "$scene" -o "$OUT/toth_tmp.exr" --size "$size" --frames "$FRAMES" \
            --warmup 1 --stats $([ $cfg = brute ] && echo "$BRUTE"); } >> "$OUT/toth_passes.txt"
    done
    rm -f "$OUT/toth_tmp.exr"
    # The fixed cost beside toth's: the defaults with the shadow map redone
    # every frame (--mode recompute), shadow_map's pass time in the CSV.
    "$S" bench "$scene" --reference "$OUT/toth_ref_$s.exr" --size "$size" --frames "$FRAMES" --warmup 1 \
        --mode recompute --csv "$OUT/toth_recompute.csv" --append --sweep shadow_map.resolution=1024 \
        --sweep toth.sampling=equiangular > "$OUT/toth_recompute.log"
done
# Speed-up at equal error: the fastest equi-angular setting with no higher
# rmse than the brute force, and the defaults (quarter resolution, 32 steps).
awk -F, 'NR > 1 { n = split($1, p, "/"); sc = p[n]; sub(/\.json$/, "", sc)
        u = $2 ~ /sampling=uniform/; full = $2 ~ /resolution=full/
        if (u && full && $2 ~ /samples=128 /) { bt[sc] = $6; bg[sc] = $7; be[sc] = $9 }
        if (!u) { t[sc, ++k[sc]] = $6; g[sc, k[sc]] = $7; e[sc, k[sc]] = $9; st[sc, k[sc]] = $2 }
        if (!u && !full && $2 ~ /samples=32 /) { dt[sc] = $6; dg[sc] = $7; de[sc] = $9 } }
    END {
        print "| scene | brute force: frame ms (toth GPU ms), rmse | fastest equi-angular at no higher rmse | frame ms (toth GPU ms), rmse | speed-up frame (toth) | defaults: frame ms, rmse | defaults speed-up frame (toth) |"
        print "|---|---|---|---|---:|---|---:|"
        for (sc in bt) {
            best = 0
            for (i = 1; i <= k[sc]; i++) if (e[sc, i] <= be[sc] && (!best || t[sc, i] < t[sc, best])) best = i
            printf "| %s | %.0f (%.0f), %.3g | %s | ", sc, bt[sc], bg[sc], be[sc], best ? st[sc, best] : "none"
            if (best) printf "%.0f (%.0f), %.3g | %.1fx (%.1fx) | ", t[sc, best], g[sc, best], e[sc, best], bt[sc] / t[sc, best], bg[sc] / g[sc, best]
            else printf "- | - | "
            printf "%.0f, %.3g | %.1fx (%.1fx) |\n", dt[sc], de[sc], bt[sc] / dt[sc], bg[sc] / dg[sc]
        } }' "$OUT/toth.csv" > "$OUT/toth_summary.md"
log "toth: $OUT/toth_summary.md, $OUT/toth_passes.txt"
fi

# ---- screen-space god rays (mitchell, sousa) against the CPU reference --------
if [ "$ONLY" = all ] || [ "$ONLY" = godrays ]; then
rm -f "$OUT"/mitchell.csv "$OUT"/sousa.csv
for s in window colonnade hidden_hole light_front; do
    ref scenes/godrays_$s.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" --spp "$REF_SPP" --bounces 0
done
for s in window colonnade; do
    bench scenes/godrays_${s}_mitchell.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/mitchell.csv" scaled_rmse \
        --sweep mitchell.n=16,32,64,128
    bench scenes/godrays_${s}_sousa.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" "$OUT/sousa.csv" scaled_rmse \
        --sweep sousa.taps=4,6,8,10,12
done
for s in hidden_hole light_front; do
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
        --set atlas_gi.progressive=false \
        --sweep atlas_gi.samples=10,50,100,200,400 --sweep atlas_gi.atlas_size=512,1024 \
        --sweep atlas_gi.estimator=area,thesis
    bench scenes/$s.json "$GI_SIZE" "$OUT/ref_${s}_vis.exr" "$OUT/atlas_gi.csv" rmse \
        --set atlas_gi.progressive=false --set atlas_gi.visibility=true \
        --sweep atlas_gi.samples=10,100,400 --sweep atlas_gi.atlas_size=512
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
