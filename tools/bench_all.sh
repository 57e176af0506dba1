#!/usr/bin/env bash
# Regenerates every benchmark table and plot of docs/benchmarks.md from the
# scenes in scenes/: references with `strahl reference`, sweeps with
# `strahl bench` (CSV + log-log plot per technique), tables from the CSVs.
# Takes about half an hour on 2 cores with llvmpipe. Not part of CI.
#   GODRAY_SIZE (512x512), GI_SIZE (128x128), FRAMES (5), REF_SPP (16),
#   GI_REF_SPP (1024), ONLY (godrays, toth, gi, or plots: run one part;
#   godrays is toth, mitchell and sousa), TOTH_MODE (steady), LIGHT_VIEW_SIZE (384x256),
#   SHAFT_ERR (0.02), GI_ERR (0.03), MAX_REF_SPP (65536): see ref() below;
#   TRUTH_SIZES (320x240 512x512), TRUTH_ERR (9e-5), TRUTH_RUNS, TRUTH_MARCH
#   (128,256,512,1024), TRUTH_CHEAP, TRUTH_ALT (3), TRUTH_SWEEP (1): toth
#   against the CPU reference
#   (ONLY=truth, also part of toth and all).
#   FROXEL_SIZE (GODRAY_SIZE), FROXEL_TIME_SIZE (512x512), FROXEL_ERR (3e-4),
#   FROXEL_SCENES (the six god-ray scenes; e.g. "spot_fog" for one):
#   froxel beside toth, mitchell and sousa against the CPU reference (ONLY=froxel,
#   also part of all); FROXEL_STILL_SIZE (512x512), FROXEL_STILL_SPP (128),
#   FROXEL_STILL_FRAMES (1024, the cap of the still's frames): froxel's box
#   still at its defaults against a box reference (ONLY=froxel_still: only that).
# References are converged enough for the tables they serve: a first run with
# REF_SPP (GI_REF_SPP) samples measures the reference's own noise (rms of its
# per-pixel standard error), and a second shard with another seed, merged in,
# brings it to a third of the smallest error that table has to resolve
# (SHAFT_ERR for mitchell/sousa's scaled rmse, GI_ERR for atlas_gi's rmse).
# bench then reports errors with the remaining reference variance removed and
# flags rows it cannot resolve (marked in the tables).
# On a terminal each step prints a line with the elapsed time and an ETA (by
# step count); otherwise only a summary line at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
S=build/bin/strahl
OUT=${OUT:-docs/bench}
GODRAY_SIZE=${GODRAY_SIZE:-512x512}
GI_SIZE=${GI_SIZE:-128x128}
GI_REF_SPP=${GI_REF_SPP:-1024}
SHAFT_ERR=${SHAFT_ERR:-0.02}
GI_ERR=${GI_ERR:-0.03}
MAX_REF_SPP=${MAX_REF_SPP:-65536}
ONLY=${ONLY:-all}
TRUTH_SIZES=${TRUTH_SIZES:-320x240 512x512}
TRUTH_ERR=${TRUTH_ERR:-9e-5}
TRUTH_MARCH=${TRUTH_MARCH:-128,256,512,1024}
TRUTH_CHEAP=${TRUTH_CHEAP:-samples=12,14,16,18,20,24 resolution=quarter probes=1,3 refine_kink=0.01,0}
TRUTH_ALT=${TRUTH_ALT:-3}
TRUTH_SWEEP=${TRUTH_SWEEP:-1}
FROXEL_SIZE=${FROXEL_SIZE:-$GODRAY_SIZE}
FROXEL_TIME_SIZE=${FROXEL_TIME_SIZE:-512x512}
FROXEL_ERR=${FROXEL_ERR:-3e-4}
FROXEL_SCENES=${FROXEL_SCENES:-window colonnade hidden_hole light_front colonnade_sun spot_fog}
FROXEL_STILL_SIZE=${FROXEL_STILL_SIZE:-512x512}
FROXEL_STILL_SPP=${FROXEL_STILL_SPP:-128}
FROXEL_STILL_FRAMES=${FROXEL_STILL_FRAMES:-1024}
FRAMES=${FRAMES:-5}
REF_SPP=${REF_SPP:-16}
[ -x "$S" ] || { cmake --preset release >/dev/null && cmake --build --preset release; }
mkdir -p "$OUT"
TTY=0; [ -t 2 ] && TTY=1
T0=$(date +%s)
STEP=0
case $ONLY in godrays) STEPS=21 ;; gi) STEPS=8 ;; plots) STEPS=0 ;; *) STEPS=29 ;; esac
log() { [ "$TTY" = 1 ] && echo "bench_all: $*" >&2; return 0; }
hms() { printf '%d:%02d' $(($1 / 60)) $(($1 % 60)); }
# One line per reference or sweep: elapsed time and an ETA from the mean step.
progress() {
    STEP=$((STEP + 1))
    [ "$STEP" -gt "$STEPS" ] && STEPS=$STEP
    [ "$TTY" = 1 ] || return 0
    local el=$(($(date +%s) - T0)) eta="?"
    [ "$STEP" -gt 1 ] && eta=$(hms $((el * (STEPS - STEP + 1) / (STEP - 1))))
    echo "bench_all [$STEP/$STEPS] $(hms $el) elapsed, ~$eta left: $*" >&2
}

# Reference: the full physical model without bounces for the god-ray scenes
# (none of the volumetric plugins adds indirect light), with the atlas_gi
# settings for the GI scenes.
# The smallest error each reference must resolve, by the tables it serves.
ref_target() {
    case $1 in
    */ref_godrays_*) echo "$SHAFT_ERR" ;; # mitchell, sousa: scaled rmse >= ~0.026
    */ref_gi_*) echo "$GI_ERR" ;;         # atlas_gi: rmse >= ~0.043
    */truth_ref_*) echo "$TRUTH_ERR" ;;   # toth and the brute force: rmse >= ~9e-5
    */froxel_ref_*) echo "$FROXEL_ERR" ;; # froxel beside toth, mitchell, sousa
    *) echo 0 ;;                          # 0: take the given --spp as it is
    esac
}
ref() { # scene size out [reference options, --spp N first run]
    local scene=$1 size=$2 out=$3; shift 3
    progress "reference $scene"
    [ -f "$out" ] && [ "$out" -nt "$scene" ] && return 0
    log "reference $scene -> $out"
    local first="$out.seed1.exr" target spp noise need
    "$S" reference "$scene" -o "$first" --size "$size" --seed 1 "$@" >/dev/null
    target=$(ref_target "$out")
    spp=$(awk '{ for (i = 1; i < NF; i++) if ($i == "--spp") print $(i + 1) }' <<<"$*")
    # The first run's noise: compare it with itself (its rms standard error).
    noise=$("$S" compare "$first" "$first" --json 2>/dev/null | sed 's/.*"ref_noise_rms":{[^}]*"all":\([^,}]*\)}.*/\1/')
    # Standard error ~ 1/sqrt(spp): a third of the target needs spp (3 noise / target)^2
    # (20% more: the first run's noise is itself an estimate).
    need=$(awk -v n="$noise" -v t="$target" -v p="${spp:-64}" -v m="$MAX_REF_SPP" 'BEGIN {
        if (t <= 0) { print 0; exit } s = 1.2 * p * (3 * n / t) ^ 2; if (s > m) s = m; print (s > p) ? int(s - p + 0.999) : 0 }')
    if [ "$need" -gt 0 ]; then
        log "reference $out: noise $noise at ${spp} spp, adding $need spp for a third of $target"
        local args=() skip=0
        for a in "$@"; do # the same options with --spp replaced
            if [ $skip = 1 ]; then skip=0; continue; fi
            if [ "$a" = --spp ]; then skip=1; continue; fi
            args+=("$a")
        done
        "$S" reference "$scene" -o "$out.seed2.exr" --size "$size" --seed 2 --spp "$need" "${args[@]}" >/dev/null
        "$S" merge "$first" "$out.seed2.exr" -o "$out" >/dev/null
        rm -f "$first" "$out.seed2.exr"
    else
        mv "$first" "$out"
    fi
}

bench() { # scene size ref csv metric sweeps...
    local scene=$1 size=$2 reffile=$3 csv=$4 metric=$5; shift 5
    progress "bench $scene $*"
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
for s in window colonnade hidden_hole light_front light_view colonnade_sun spot_fog; do
    scene=scenes/godrays_$s.json size=$GODRAY_SIZE
    # The sun and spot scenes (issue 14) are named without the godrays_ prefix.
    case $s in colonnade_sun | spot_fog) scene=scenes/$s.json ;; esac
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

# ---- toth against ground truth (issue 21) --------------------------------------
# Per scene and size one CSV, truth_S_SIZE.csv, from strahl bench runs back to
# back (--mode recompute: the shadow map is redone every frame for all), every
# row scored against `strahl reference --bounces 0 --filter point --steps 1024`
# (single scattering with exact visibility; ref() brings its noise to a third
# of TRUTH_ERR, bench removes what remains and flags rows it cannot resolve):
#   the brute force: the uniform full-resolution march (no interleave) at
#     TRUTH_MARCH steps (128..1024; 1024 is toth.samples' maximum);
#   the defaults (samples=32 since issue 35; 64 and 128 beside them) and the map's own
#     lookups (exact_edges and probes off);
#   the cheap sweep, TRUTH_CHEAP (toth parameters, up to 4; 0 skips it):
#     samples 12..24 x resolution quarter x probes 1,3 x refine_kink 0.01,0
#     (exact_edges on), where toth meets the march at its best error (half
#     resolution and probes=0 never were the cheapest there).
# truth_S_SIZE.png: the Pareto fronts (rmse against frame ms) of both.
# truth_summary.md, from every truth_S_SIZE.csv in $OUT: (1) at the defaults'
# error: the march's rmse per step count, the cheapest march setting that
# reaches the defaults' rmse (none where its curve stays above), and the
# 1024-step march's frame time over the defaults' (and, where it does not
# arrive, the speed-up if its rmse kept falling as 1/steps beyond 1024, an
# estimate: measured it falls slower); (2) at the 1024-step
# march's error: the cheapest toth setting with no higher rmse and the
# speed-up t(march 1024) / t(that setting), by frame time and by toth's GPU
# time. The load average (1 min) at the start and end of each run is in
# truth_S_SIZE.load. TRUTH_RUNS ("scene:size ...", default every scene at every
# TRUTH_SIZES; empty: none, only the summary) picks the runs; other runs'
# CSVs stay. (truth.csv and truth_godrays_*.png are the 256x192 runs of the
# script before, cited in docs/benchmarks.md.)
if [ "$ONLY" = all ] || [ "$ONLY" = toth ] || [ "$ONLY" = truth ]; then
# The cheapest equi-angular setting of a run's CSV with no higher rmse than
# the 1024-step march (empty: none). Rows: scene,setting,...: frame ms $6,
# toth's GPU ms $7, debiased rmse $9, reference noise rms $20, its warning $21
# (1: noise > rmse / 3).
truth_winner() {
    awk -F, 'NR > 1 && $1 != "scene" { if ($2 ~ /sampling=uniform/) { if ($2 ~ /samples=1024( |$)/) e1 = $9; next }
            k++; t[k] = $6; e[k] = $9; st[k] = $2 }
        END { for (i = 1; i <= k; i++) if (e[i] <= e1 && (!best || t[i] < t[best])) best = i
            if (best) print st[best] }' "$1"
}
runs=${TRUTH_RUNS-$(for s in window hidden_hole colonnade colonnade_sun spot_fog; do for z in $TRUTH_SIZES; do echo "$s:$z"; done; done)}
for run in $runs; do
    s=${run%%:*} size=${run#*:}
    scene=scenes/godrays_$s.json # point lights; the sun and the spot: scenes/$s.json
    [ -f "$scene" ] || scene=scenes/$s.json
    csv=$OUT/truth_${s}_$size.csv r=$OUT/truth_ref_${s}_$size.exr
    if [ "$TRUTH_SWEEP" = 1 ]; then # (0: keep the CSV, run only the alternation)
    rm -f "$csv"
    # Pixel centres (--filter point; bench follows the reference's filter): a
    # box-filtered 8-spp reference is 2.9e-3 noisy at shaft and silhouette
    # edges (320x240 window), so ref() would ask the 65536-spp cap; at
    # the point filter 16 spp leave 1.2e-5 to 3.2e-5 (256x192).
    ref "$scene" "$size" "$r" --bounces 0 --spp 8 --steps 1024 --filter point
    echo "start $(cut -d' ' -f1 /proc/loadavg) $(date -u +%H:%M)" > "${csv%.csv}.load"
    bench "$scene" "$size" "$r" "$csv" rmse --mode recompute \
        --set toth.interleave=1 --set toth.resolution=full \
        --sweep toth.samples="$TRUTH_MARCH" --sweep toth.sampling=uniform
    bench "$scene" "$size" "$r" "$csv" rmse --mode recompute \
        --sweep toth.samples=32,64,128 --sweep toth.sampling=equiangular
    bench "$scene" "$size" "$r" "$csv" rmse --mode recompute \
        --sweep toth.exact_edges=0 --sweep toth.probes=0
    if [ "$TRUTH_CHEAP" != 0 ]; then
        # shellcheck disable=SC2046,SC2086 # one --sweep per word
        bench "$scene" "$size" "$r" "$csv" rmse --mode recompute $(printf -- '--sweep toth.%s ' $TRUTH_CHEAP)
    fi
    echo "end $(cut -d' ' -f1 /proc/loadavg) $(date -u +%H:%M)" >> "${csv%.csv}.load"
    "$S" plot "$csv" -o "$OUT/truth_${s}_$size.png" --baseline toth.samples=1024,toth.sampling=uniform \
        --title "toth and the uniform march against the CPU reference: $s $size"
    fi
    # The sweep runs the march and toth minutes apart while the load drifts:
    # TRUTH_ALT rounds (0: none) of the 1024-step march, the cheapest toth
    # setting at its rmse and the defaults, one after the other, into
    # truthalt_S_SIZE.csv (scored as above).
    alt=$OUT/truthalt_${s}_$size.csv win=$(truth_winner "$csv")
    rm -f "$alt"
    for _ in $(seq "$TRUTH_ALT"); do
        bench "$scene" "$size" "$r" "$alt" rmse --mode recompute --set toth.interleave=1 \
            --set toth.resolution=full --sweep toth.samples=1024 --sweep toth.sampling=uniform
        # shellcheck disable=SC2046,SC2086 # one --sweep per word of the setting
        [ -z "$win" ] || bench "$scene" "$size" "$r" "$alt" rmse --mode recompute $(printf -- '--sweep %s ' $win)
        bench "$scene" "$size" "$r" "$alt" rmse --mode recompute --sweep toth.sampling=equiangular
    done
    [ "$TRUTH_ALT" -gt 0 ] && echo "alt $(cut -d' ' -f1 /proc/loadavg) $(date -u +%H:%M)" >> "${csv%.csv}.load"
done
# The defaults: samples=32 (issue 35) at the equi-angular sampling, nothing else set.
truth_tables() {
    echo "(1) At the defaults' error: the 1024-step full-resolution uniform march's curve (frame ms, rmse per step count) against the defaults."
    echo
    echo "| scene | size | reference noise rms | march: steps frame ms, rmse | defaults: frame ms, rmse | march's best rmse / defaults' | cheapest march with rmse <= defaults | t(1024-step march) / t(defaults): frame (toth GPU) | estimate at the defaults' rmse (march rmse ~ 1/steps beyond 1024) |"
    echo "|---|---|---:|---|---|---:|---|---:|---:|"
    for c in "$@"; do
        awk -F, -v f="$c" 'NR > 1 && $1 != "scene" { n = split($1, p, "/"); sc = p[n]; sub(/\.json$/, "", sc)
                noise = $20
                if ($2 ~ /sampling=uniform/) { split($2, q, "[= ]"); m++; ms[m] = $6; me[m] = $9; mst[m] = q[2]
                    if (q[2] == 1024) { t1 = $6; g1 = $7; e1 = $9 } }
                if ($2 == "toth.samples=32 toth.sampling=equiangular") { dt = $6; dg = $7; de = $9; dw = $21 } }
            END { z = f; sub(/.*_/, "", z); sub(/\.csv$/, "", z)
                curve = ""; best = 0; low = 0
                for (i = 1; i <= m; i++) {
                    curve = curve sprintf("%s%d: %.0f, %.3g", i > 1 ? "; " : "", mst[i], ms[i], me[i])
                    if (!low || me[i] < me[low]) low = i
                    if (me[i] <= de && (!best || ms[i] < ms[best])) best = i }
                printf "| %s | %s | %.2g | %s | %.0f, %.3g%s | %.2f | ", sc, z, noise, curve, dt, de, dw ? " *" : "", me[low] / de
                if (best) printf "%d steps: %.0f ms | ", mst[best], ms[best]
                else printf "none (up to %d steps) | ", mst[m]
                printf "%.1fx (%.1fx)%s | ", t1 / dt, g1 / dg, best ? "" : ", at lower rmse"
                # The march at its steepest (rmse ~ 1/N, time ~ N; measured: slower)
                # reaches the defaults at (e1 / de) 1024 steps, (e1 / de) t1.
                if (best) printf "- |\n"; else printf "%.0fx |\n", (e1 / de) * (t1 / dt) }' "$c"
    done
    echo
    echo "(2) At the 1024-step march's error: the cheapest toth setting (any equi-angular row) with no higher rmse."
    echo
    echo "| scene | size | 1024-step march: frame ms (toth GPU ms), rmse | cheapest toth setting with rmse <= it | its frame ms (toth GPU ms), rmse | speed-up frame (toth GPU) | defaults' speed-up frame (toth GPU) | load (1 min): sweep start, end, alternation end |"
    echo "|---|---|---|---|---|---:|---:|---|"
    for c in "$@"; do
        ld=$(awk '{ printf "%s%s %s", (NR > 1 ? ", " : ""), $2, $3 }' "${c%.csv}.load" 2>/dev/null || true)
        awk -F, -v f="$c" -v ld="$ld" 'NR > 1 && $1 != "scene" { n = split($1, p, "/"); sc = p[n]; sub(/\.json$/, "", sc)
                if ($2 ~ /sampling=uniform/) { if ($2 ~ /samples=1024( |$)/) { t1 = $6; g1 = $7; e1 = $9 } next }
                k++; t[k] = $6; g[k] = $7; e[k] = $9; st[k] = $2; w[k] = $21
                if ($2 == "toth.samples=32 toth.sampling=equiangular") { dt = $6; dg = $7 } }
            END { z = f; sub(/.*_/, "", z); sub(/\.csv$/, "", z)
                best = 0
                for (i = 1; i <= k; i++) if (e[i] <= e1 && (!best || t[i] < t[best])) best = i
                printf "| %s | %s | %.0f (%.0f), %.3g | ", sc, z, t1, g1, e1
                if (best) printf "%s | %.0f (%.0f), %.3g%s | %.1fx (%.1fx) | ", st[best], t[best], g[best], e[best], w[best] ? " *" : "", t1 / t[best], g1 / g[best]
                else printf "none | - | - | "
                printf "%.1fx (%.1fx) | %s |\n", t1 / dt, g1 / dg, ld }' "$c"
    done
    echo
    echo "\\* the reference's noise is more than a third of that rmse (not resolved)."
    local a alts=()
    for c in "$@"; do
        a=$(dirname "$c")/truthalt_$(basename "$c" | sed 's/^truth_//')
        [ -f "$a" ] && alts+=("$a")
    done
    [ ${#alts[@]} -gt 0 ] || return 0
    echo
    echo "(3) Alternating: the 1024-step march, the setting of (2) and the defaults one after the other, each a fresh strahl bench run; frame ms per round, the speed-up from the medians."
    echo
    echo "| scene | size | 1024-step march: frame ms per round | setting of (2): frame ms per round, rmse | defaults: frame ms per round | speed-up at equal error (medians) | defaults' speed-up (medians) |"
    echo "|---|---|---|---|---|---:|---:|"
    for a in "${alts[@]}"; do
        awk -F, -v f="$a" 'function med(x, n,   i, j, v, y) { for (i = 1; i <= n; i++) y[i] = x[i]
                for (i = 2; i <= n; i++) { v = y[i]; for (j = i - 1; j >= 1 && y[j] > v; j--) y[j + 1] = y[j]; y[j + 1] = v }
                return n % 2 ? y[(n + 1) / 2] : (y[n / 2] + y[n / 2 + 1]) / 2 }
            function list(x, n,   i, s) { for (i = 1; i <= n; i++) s = s sprintf("%s%.0f", i > 1 ? ", " : "", x[i]); return s }
            NR > 1 && $1 != "scene" { n = split($1, p, "/"); sc = p[n]; sub(/\.json$/, "", sc)
                if ($2 ~ /sampling=uniform/) m[++nm] = $6
                else if ($2 == "toth.sampling=equiangular") d[++nd] = $6
                else { w[++nw] = $6; ws = $2; we = $9 } }
            END { z = f; sub(/.*_/, "", z); sub(/\.csv$/, "", z)
                printf "| %s | %s | %s | ", sc, z, list(m, nm)
                if (nw) printf "%s: %s, %.3g | ", ws, list(w, nw), we
                else printf "none | "
                printf "%s | ", list(d, nd)
                if (nw) printf "%.1fx | ", med(m, nm) / med(w, nw)
                else printf "- | "
                printf "%.1fx |\n", med(m, nm) / med(d, nd) }' "$a"
    done
}
shopt -s nullglob
tcsvs=("$OUT"/truth_*_[0-9]*x[0-9]*.csv)
shopt -u nullglob
[ ${#tcsvs[@]} -gt 0 ] && truth_tables "${tcsvs[@]}" > "$OUT/truth_summary.md"
log "truth: $OUT/truth_summary.md"
fi

# ---- froxel beside toth, mitchell and sousa against ground truth (issue 24) ---
# Per god-ray scene one reference (`strahl reference --bounces 0`, point filter,
# its noise brought to a third of FROXEL_ERR by ref()) and one CSV with every
# technique's sweep against it (rmse, --mode recompute: the shadow map redone
# every frame): froxel's grid (slices along each curve, tile per curve,
# min_rows off so the tile is what it says) and its defaults, toth's samples
# at its defaults otherwise, mitchell's and sousa's taps where the scene has
# their variant. froxel_<scene>.png: one Pareto plot per scene.
# froxel_vs_toth.md: frame time (median of FRAMES, strahl render --stats,
# point filter) of both at their defaults at FROXEL_TIME_SIZE, and their
# ratio, from this one run, beside the rmse of both from the CSV.
if [ "$ONLY" = all ] || [ "$ONLY" = froxel ]; then
rm -f "$OUT"/froxel_vs_toth.md
for s in $FROXEL_SCENES; do
    base=scenes/godrays_$s
    case $s in colonnade_sun | spot_fog) base=scenes/$s ;; esac
    r=$OUT/froxel_ref_${s}_$FROXEL_SIZE.exr csv=$OUT/froxel_$s.csv
    rm -f "$csv" # (other scenes' CSVs stay: FROXEL_SCENES may name a few)
    ref "$base.json" "$FROXEL_SIZE" "$r" --bounces 0 --spp 8 --filter point
    bench "${base}_froxel.json" "$FROXEL_SIZE" "$r" "$csv" rmse --mode recompute \
        --set froxel.min_rows=0 --sweep froxel.slices=32,64,128,256 --sweep froxel.tile=16,8,4
    bench "${base}_froxel.json" "$FROXEL_SIZE" "$r" "$csv" rmse --mode recompute --sweep froxel.slices=128
    # The 4-tap footprint source (single frames; a box-filtered still gets
    # the footprint from its jittered frames at the defaults' cost).
    bench "${base}_froxel.json" "$FROXEL_SIZE" "$r" "$csv" rmse --mode recompute \
        --set froxel.taps=footprint --sweep froxel.slices=64,128
    bench "$base.json" "$FROXEL_SIZE" "$r" "$csv" rmse --mode recompute --sweep toth.samples=16,32,64,128
    if [ -f "${base}_mitchell.json" ]; then
        bench "${base}_mitchell.json" "$FROXEL_SIZE" "$r" "$csv" rmse --mode recompute --sweep mitchell.n=16,32,64,128
        bench "${base}_sousa.json" "$FROXEL_SIZE" "$r" "$csv" rmse --mode recompute --sweep sousa.taps=4,8,12
    fi
    "$S" plot "$csv" -o "$OUT/froxel_$s.png" --title "froxel, toth, mitchell, sousa on $s ($FROXEL_SIZE)"
    for m in froxel toth; do
        sc=${base}_froxel.json; [ $m = toth ] && sc=$base.json
        ms=$("$S" render "$sc" -o "$OUT/froxel_tmp.exr" --size "$FROXEL_TIME_SIZE" --filter point \
            --frames "$FRAMES" --warmup 1 --stats 2>&1 | sed -n 's/.*median frame \([0-9.]*\) ms.*/\1/p')
        echo "$s $m $ms" >> "$OUT/froxel_times.txt.tmp"
    done
    rm -f "$OUT/froxel_tmp.exr"
done
# rmse at the defaults from the CSVs ($9; froxel: slices=128 without tile,
# toth: samples=32, the defaults since issue 35), frame medians from the renders above.
{
    echo "| scene | toth defaults: frame ms, rmse | froxel defaults: frame ms, rmse | frame time froxel / toth |"
    echo "|---|---|---|---:|"
    while read -r s m ms; do
        if [ "$m" = froxel ]; then tf=$ms; continue; fi
        e=$(awk -F, '$2 == "froxel.slices=128" { f = $9 } $2 ~ /^toth.samples=32( |$)/ { t = $9 } END { print f, t }' "$OUT/froxel_$s.csv")
        awk -v s="$s" -v tf="$tf" -v tt="$ms" -v e="$e" 'BEGIN { split(e, x, " ")
            printf "| %s | %.0f, %.3g | %.0f, %.3g | %.2f |\n", s, tt, x[2], tf, x[1], tf / tt }'
    done < "$OUT/froxel_times.txt.tmp"
} > "$OUT/froxel_vs_toth.md"
rm -f "$OUT/froxel_times.txt.tmp"
log "froxel: $OUT/froxel_vs_toth.md, $OUT/froxel_*.png"
fi

# ---- froxel: the box-filtered still at its defaults against a box reference --
# What `strahl render` hands back (jittered frames averaged until the
# stopping rule's estimated NRMSE <= 0.01, or FROXEL_STILL_FRAMES) against
# `strahl reference --filter box --bounces 0` at FROXEL_STILL_SIZE with
# FROXEL_STILL_SPP samples (--steps 32: unbiased, 6.5x cheaper per sample
# than 256 at equal noise on spot_fog, where the pixel position's variance
# dominates). froxel_still.md: per scene the still's frames and estimated
# NRMSE, its NRMSE (debiased, and the reference's noise, both over the
# reference's mean), and the frame time (median of FRAMES, point filter) of
# froxel and toth at their defaults, back to back. ONLY=froxel_still runs
# this block alone and stops (no tables spliced).
if [ "$ONLY" = all ] || [ "$ONLY" = froxel ] || [ "$ONLY" = froxel_still ]; then
{
    echo "| scene | still: frames, estimated NRMSE | froxel NRMSE: debiased, raw (reference noise) | frame ms froxel, toth | froxel / toth |"
    echo "|---|---|---:|---|---:|"
    for s in $FROXEL_SCENES; do
        base=scenes/godrays_$s
        case $s in colonnade_sun | spot_fog) base=scenes/$s ;; esac
        r=$OUT/froxel_still_ref_${s}_$FROXEL_STILL_SIZE.exr
        ref "$base.json" "$FROXEL_STILL_SIZE" "$r" --bounces 0 --spp "$FROXEL_STILL_SPP" --filter box --steps 32
        progress "still ${base}_froxel.json"
        st=$("$S" render "${base}_froxel.json" -o "$OUT/froxel_tmp.exr" --size "$FROXEL_STILL_SIZE" \
            --max-frames "$FROXEL_STILL_FRAMES" 2>&1 | sed -n 's/.*after \([0-9]*\) frame.*error \([0-9.]*\).*/\1 \2/p')
        js=$("$S" compare "$OUT/froxel_tmp.exr" "$r" --json 2>/dev/null)
        e=$(sed 's/.*"rmse_debiased":{[^}]*"all":\([^,}]*\)}.*/\1/' <<<"$js")
        raw=$(sed 's/.*"rmse":{[^}]*"all":\([^,}]*\)}.*/\1/' <<<"$js")
        n=$(sed 's/.*"ref_noise_rms":{[^}]*"all":\([^,}]*\)}.*/\1/' <<<"$js")
        m=$(sed 's/.*"mean_b":{[^}]*"all":\([^,}]*\)}.*/\1/' <<<"$js")
        for x in froxel toth; do
            sc=${base}_froxel.json; [ $x = toth ] && sc=$base.json
            "$S" render "$sc" -o "$OUT/froxel_tmp.exr" --size "$FROXEL_STILL_SIZE" --filter point \
                --frames "$FRAMES" --warmup 1 --stats 2>&1 | sed -n 's/.*median frame \([0-9.]*\) ms.*/\1/p'
        done | paste -sd' ' | awk -v s="$s" -v st="$st" -v e="$e" -v r="$raw" -v n="$n" -v m="$m" '{ split(st, f, " ")
            printf "| %s | %d, %.4f | %.3f, %.3f (%.3f) | %.0f, %.0f | %.2f |\n", s, f[1], f[2], e / m, r / m, n / m, $1, $2, $1 / $2 }'
    done
} > "$OUT/froxel_still.md"
rm -f "$OUT/froxel_tmp.exr"
log "froxel stills: $OUT/froxel_still.md"
[ "$ONLY" = froxel_still ] && exit 0
fi

# ---- screen-space god rays (mitchell, sousa) against the CPU reference --------
if [ "$ONLY" = all ] || [ "$ONLY" = godrays ]; then
rm -f "$OUT"/mitchell.csv "$OUT"/sousa.csv
for s in window colonnade hidden_hole light_front; do
    ref scenes/godrays_$s.json "$GODRAY_SIZE" "$OUT/ref_godrays_$s.exr" --spp "$REF_SPP" --bounces 0
done
# The low sun behind the colonnade (scenes/colonnade_sun*.json).
ref scenes/colonnade_sun.json "$GODRAY_SIZE" "$OUT/ref_godrays_colonnade_sun.exr" --spp "$REF_SPP" --bounces 0
bench scenes/colonnade_sun_mitchell.json "$GODRAY_SIZE" "$OUT/ref_godrays_colonnade_sun.exr" "$OUT/mitchell.csv" scaled_rmse \
    --sweep mitchell.n=16,32,64,128
bench scenes/colonnade_sun_sousa.json "$GODRAY_SIZE" "$OUT/ref_godrays_colonnade_sun.exr" "$OUT/sousa.csv" scaled_rmse \
    --sweep sousa.taps=4,6,8,10,12
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
# The brute-force setting each plot marks (strahl plot --baseline).
baseline() {
    case $1 in
    toth) echo --baseline toth.samples=128,toth.sampling=uniform,toth.resolution=full ;;
    truth) echo --baseline toth.samples=1024,toth.sampling=uniform ;;
    atlas_gi) echo --baseline atlas_gi.samples=400,atlas_gi.atlas_size=1024,atlas_gi.estimator=area ;;
    esac
}
# (truth: one plot per scene and size, drawn in its block.)
for m in toth mitchell sousa atlas_gi; do
    csv=$OUT/$m.csv
    [ -f "$csv" ] || continue
    metric=$(head -1 "$csv" | cut -d, -f9 | sed 's/^error_//')
    # One plot per scene: split the CSV by its first column.
    for scene in $(tail -n +2 "$csv" | cut -d, -f1 | sort -u); do
        name=$(basename "$scene" .json)
        # Redrawn only where the CSV is newer (gnuplot's PNG bytes vary by run).
        [ "$OUT/${m}_${name}.png" -nt "$csv" ] && continue
        part=$OUT/${m}_${name}.csv
        { head -1 "$csv"; grep "^$scene," "$csv"; } > "$part"
        # shellcheck disable=SC2046 # baseline: an option and its value, or nothing
        "$S" plot "$part" -o "$OUT/${m}_${name}.png" $(baseline "$m")
        rm -f "$part"
    done
done

table() { # csv -> markdown rows: scene, setting, frame ms, module gpu ms, error, raw error
    echo "| scene | setting | frame ms (median) | module GPU ms (median) | error | raw error |"
    echo "|---|---|---:|---:|---:|---:|"
    # error: the reference's own variance removed; raw: as measured; * : the
    # reference's noise exceeds a third of the error (not resolved).
    tail -n +2 "$1" | awk -F, '{ n = split($1, p, "/"); flag = ($21 == 1) ? " *" : ""
        raw = (NF >= 19) ? sprintf("%.4g", $19) : sprintf("%.4g", $9)
        printf "| %s | %s | %.1f | %.1f | %.4g%s | %s |\n", p[n], $2, $6, $7, $9, flag, raw }'
}
{
    echo "<!-- generated by tools/bench_all.sh; edit the script, not this block -->"
    for m in toth truth mitchell sousa atlas_gi; do
        if [ $m = truth ]; then # issue 21: the summary, then every run's CSV
            shopt -s nullglob
            tcsvs=("$OUT"/truth_*_[0-9]*x[0-9]*.csv)
            shopt -u nullglob
            [ ${#tcsvs[@]} -gt 0 ] || continue
            echo
            echo "### truth: toth and the uniform march against the CPU reference (rmse)"
            echo
            [ -f "$OUT/truth_summary.md" ] && cat "$OUT/truth_summary.md"
            for c in "${tcsvs[@]}"; do
                echo; table "$c"; echo; echo "![$(basename "$c" .csv)](bench/$(basename "$c" .csv).png)"
            done
            continue
        fi
        [ -f "$OUT/$m.csv" ] || continue
        echo
        echo "### $m ($(head -1 "$OUT/$m.csv" | cut -d, -f9 | sed 's/^error_//'))"
        echo
        echo "Error: with the reference's own variance removed (README, \"Honest error floors\"); raw"
        echo "error: as measured; \\* the reference's noise is more than a third of that error."
        echo
        table "$OUT/$m.csv"
        echo
        for p in "$OUT"/${m}_*.png; do [ -f "$p" ] && echo "![$(basename "$p" .png)](bench/$(basename "$p"))"; done
    done
} > "$OUT/tables.md"
# froxel (issue 24): the comparison at the defaults, then every scene's CSV.
if [ -f "$OUT/froxel_vs_toth.md" ]; then
    { echo; echo "### froxel beside toth, mitchell and sousa (rmse against strahl reference --bounces 0)"
      echo; cat "$OUT/froxel_vs_toth.md"
      [ -f "$OUT/froxel_still.md" ] && { echo; echo "froxel's box still at its defaults against a box reference:"; echo; cat "$OUT/froxel_still.md"; }
      for c in "$OUT"/froxel_*.csv; do echo; table "$c"; echo; echo "![$(basename "$c" .csv)](bench/$(basename "$c" .csv).png)"; done
    } >> "$OUT/tables.md"
fi
log "done: $OUT/tables.md and plots"

# Splice the tables into docs/benchmarks.md between its markers (only from
# docs/bench: the tables link their plots as bench/NAME.png).
[ "$OUT" = docs/bench ] || { echo "bench_all: tables in $OUT/tables.md (OUT is not docs/bench: docs/benchmarks.md left as it is)" >&2; exit 0; }
awk -v tables="$OUT/tables.md" '
    /<!-- BEGIN GENERATED -->/ { print; while ((getline line < tables) > 0) print line; skip = 1; next }
    /<!-- END GENERATED -->/ { skip = 0 }
    !skip { print }' docs/benchmarks.md > docs/benchmarks.md.tmp && mv docs/benchmarks.md.tmp docs/benchmarks.md
log "docs/benchmarks.md updated"
echo "bench_all: $STEP steps (references and sweeps) in $(hms $(($(date +%s) - T0))); tables in docs/benchmarks.md" >&2
