#!/usr/bin/env bash
# bench-ref.sh: photosplat-ref's speed against its error on the default scene,
# next to POV-Ray 3.7 (Debian's `povray`, which also renders photon-mapped
# caustics) on the same scene (data/scenes/cornell-caustic.pov).
#
# Each renderer renders the scene at a few quality levels and once at a much
# higher one, its converged reference; every level's error is its relMSE
# against its own reference. Both renderers are measured the same way: as
# 8-bit sRGB PNGs at one exposure (what a user looks at); photosplat-ref's
# relMSE in linear radiance (its --hdr PFM) is given as well. The ratio
# "ours / POV-Ray" divides our wall seconds by POV-Ray's at equal PNG relMSE
# (log-log interpolation along the Pareto front of POV-Ray's levels).
#
# The references are cached under bench/results/cache/, keyed by a hash of
# the scene file, the renderer binary, the size and the reference settings:
# they are rendered again only when one of those changes.
#
# Beyond the table: the goals of issue 21 (the default and final presets'
# seconds, the default's whole-image and specular-term relMSE against their
# references, and the back wall's band-pass energy, scripts/wall-highpass.py).
#
# Output: a Markdown table on stdout, bench/results/ref.md and ref.csv, and
# bench/results/ref-vs-povray.png (ours | POV-Ray | |difference| x4, both
# references). Called by `make bench` (scripts/bench.sh); alone:
#
#   scripts/bench-ref.sh            # about 13 minutes on 2 shared cores (the
#                                   # photosplat-ref references alone 6-9), 3 once cached
#   SIZE=128 scripts/bench-ref.sh   # a quick smaller run (its own cache keys)
#
# Environment: SIZE (square image side, default 512), THREADS (default 2),
# EXPOSURE (default 0.3). POV-Ray is installed through apt-get when missing;
# without it only photosplat-ref's rows are printed and the exit status is 1.
set -u
cd "$(dirname "$0")/.." || exit 2

SIZE=${SIZE:-512}
THREADS=${THREADS:-2}
EXPOSURE=${EXPOSURE:-0.3}
SCN=data/scenes/cornell-caustic.scn
POV=data/scenes/cornell-caustic.pov
OUT=bench/results
CACHE=$OUT/cache
RUN=$OUT/run
REF=bin/photosplat-ref
CMP=bin/photosplat-compare

# photosplat-ref levels: label | options. The three --quality presets (the
# default: spp 4, gather 16, the irradiance cache with gradients asked for
# down to every 2 pixels, 1024 rays a record, the Mitchell filter), then the
# default without its parts: no cache (gathering at every eye ray's diffuse
# surface), the box filter.
OURS_LEVELS=(
    "draft|--quality draft"
    "default (default)|--quality default"
    "final|--quality final"
    "default, box filter|--filter box"
    "default, no cache|--cache 0"
    "spp 4, gather 64, no cache|--spp 4 --gather 64 --cache 0"
)
# The converged reference gathers everywhere (no cache, so no interpolation
# error of its own) with 8x the no-cache default's eye work, 4x its photons,
# and another seed (its photons and eye samples independent of the levels').
OURS_REF_LABEL="spp 16, gather 128, no cache, 4x photons, seed 7"
OURS_REF_OPTS="--spp 16 --gather 128 --cache 0 --caustic-photons 800000 --global-photons 200000 --seed 7"
# The specular term alone (what mirrors and glass show), converged the same
# way with 64 eye samples, against the default's.
SPEC_REF_LABEL="specular: spp 64, gather 64, no cache, 4x photons, seed 7"
SPEC_REF_OPTS="--component specular --spp 64 --gather 64 --cache 0 --caustic-photons 800000 --global-photons 200000 --seed 7"
# Goals (issue 21): seconds on 2 cores, and relMSE against the references.
GOAL_DEFAULT_S=10
GOAL_FINAL_S=30
GOAL_SPECULAR=0.004
GOAL_WHOLE=0.002

# POV-Ray levels: label | command-line options (Declare= sets the scene's knobs).
POV_LEVELS=(
    "no AA, rad 20/1.5, 50k photons|-A Declare=RadCount=20 Declare=RadError=1.5 Declare=RadPretrace=0.04 Declare=Photons=50000"
    "AA 0.3, rad 35/1.0, 100k photons|+A0.3 +AM2 +R2 Declare=RadCount=35 Declare=RadError=1.0 Declare=RadPretrace=0.02 Declare=Photons=100000"
    "AA 0.3, rad 100/0.8, 200k photons|+A0.3 +AM2 +R2 Declare=RadCount=100 Declare=RadError=0.8 Declare=RadPretrace=0.01 Declare=Photons=200000"
    "AA 0.3, rad 150/0.5, 200k photons|+A0.3 +AM2 +R2 Declare=RadCount=150 Declare=RadError=0.5 Declare=RadPretrace=0.01 Declare=Photons=200000"
)
POV_REF_LABEL="AA 0.1 R3, rad 300/0.3, 400k photons"
POV_REF_OPTS="+A0.1 +AM2 +R3 Declare=RadCount=300 Declare=RadError=0.3 Declare=RadPretrace=0.005 Declare=Photons=400000"

status=0
t_start=$(date +%s)
load_start=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null)
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }
# field NAME LINE: the value of NAME=… in photosplat-compare's line.
field() { sed -n "s/.*\\b$1=\\([^ ]*\\).*/\\1/p" <<<"$2"; }
# json NAME FILE: a number from a --stats file.
json() { sed -n "s/.*\"$1\": *\\([-0-9.eE+]*\\).*/\\1/p" "$2" | head -1; }
# fmt SPEC VALUE: printf for numbers, anything else ("-", "") as it is.
# shellcheck disable=SC2059 # the format is the argument
fmt() { if [[ $2 =~ ^[-+]?[0-9.]+([eE][-+]?[0-9]+)?$ ]]; then LC_ALL=C printf "$1" "$2"; else printf '%s' "$2"; fi; }
hash_of() { cat "$@" | sha256sum | cut -c1-16; }
log() { echo "bench-ref: $*" >&2; }
# prune PREFIX KEY: drops cached references of this size made with other keys.
prune() {
    local f
    for f in "$CACHE/$1"-*; do
        [ -e "$f" ] || continue
        case "$f" in "$CACHE/$1-$2".*) ;; *) rm -f "$f" ;; esac
    done
}

# ---- set-up -----------------------------------------------------------------
if ! make --no-print-directory -s all >/dev/null; then
    log "building bin/ failed"
    exit 2
fi
mkdir -p "$CACHE" "$RUN"

have_pov=1
if ! command -v povray >/dev/null 2>&1; then
    # Bench-only baseline, never needed to build or test: Debian's package.
    log "installing povray (Debian package, bench only)"
    SUDO=()
    if [ "$(id -u)" -ne 0 ] && command -v sudo >/dev/null 2>&1; then SUDO=(sudo); fi
    export DEBIAN_FRONTEND=noninteractive
    if ! "${SUDO[@]}" apt-get install -y --no-install-recommends povray >/dev/null 2>&1; then
        "${SUDO[@]}" apt-get update -qq >/dev/null 2>&1
        "${SUDO[@]}" apt-get install -y --no-install-recommends povray >/dev/null 2>&1
    fi
    command -v povray >/dev/null 2>&1 || { log "povray unavailable: POV-Ray rows skipped"; have_pov=0; status=1; }
fi

# ---- photosplat-ref -----------------------------------------------------------
# ours BASE "OPTS": renders BASE.png (at the exposure), BASE.pfm, BASE.json
# and BASE.log; sets WALL.
ours() {
    local base=$1 t0 t1 opts
    read -ra opts <<<"$2"
    rm -f "$base.png" "$base.pfm" "$base.json"
    t0=$(now)
    if ! "$REF" "$SCN" -o "$base.png" --hdr "$base.pfm" --stats "$base.json" --size "${SIZE}x${SIZE}" \
        --exposure "$EXPOSURE" --threads "$THREADS" "${opts[@]}" >"$base.log" 2>&1; then
        log "photosplat-ref $2 failed (see $base.log)"
        return 1
    fi
    t1=$(now)
    WALL=$(elapsed "$t0" "$t1")
}

# povr BASE "OPTS": renders BASE.png (and BASE.log) with POV-Ray; sets WALL,
# PREPASS (POV-Ray's photon shooting + radiosity pretrace) and TRACE seconds.
povr() {
    local base=$1 dir name t0 t1 opts
    read -ra opts <<<"$2"
    dir=$(dirname "$base")
    name=$(basename "$base")
    rm -f "$base.png"
    t0=$(now)
    # POV-Ray's I/O restrictions allow writing only in its working directory.
    if ! (cd "$dir" && povray +I"$OLDPWD/$POV" +O"$name.png" +FN +W"$SIZE" +H"$SIZE" -D -V +WT"$THREADS" \
        File_Gamma=sRGB Declare=Exposure="$EXPOSURE" "${opts[@]}" >"$name.log" 2>&1) || [ ! -s "$base.png" ]; then
        log "povray $2 failed (see $base.log)"
        return 1
    fi
    t1=$(now)
    WALL=$(elapsed "$t0" "$t1")
    local ph rad tr
    ph=$(sed -n 's/^ *Photon Time:.*(\([0-9.]*\) seconds).*/\1/p' "$base.log")
    rad=$(sed -n 's/^ *Radiosity Time:.*(\([0-9.]*\) seconds).*/\1/p' "$base.log")
    tr=$(sed -n 's/^ *Trace Time:.*(\([0-9.]*\) seconds).*/\1/p' "$base.log")
    PREPASS=$(awk -v a="${ph:-0}" -v b="${rad:-0}" 'BEGIN { printf "%.2f", a + b }')
    TRACE=${tr:-0}
}

rows=()   # renderer|label|wall|prepass|render|relmse_png|relmse_lin|psnr_png
hp_rows=() # label|highpass|wall|relmse_png|relmse_lin
spec_row="" # wall|relmse
ok=1

# cached_ref PREFIX "OPTS" LABEL: the reference rendered with OPTS, cached
# (sets REF_BASE and REF_NOTE; returns 1 when it could not be made).
cached_ref() {
    local key
    key=$(hash_of "$SCN" "$REF" <(echo "$SIZE $EXPOSURE $2"))
    REF_BASE=$CACHE/$1-$SIZE-$key
    prune "$1-$SIZE" "$key"
    if [ -s "$REF_BASE.pfm" ] && [ -s "$REF_BASE.png" ] && [ -s "$REF_BASE.wall" ]; then
        REF_NOTE="cached"
        return 0
    fi
    log "photosplat-ref reference ($3), a few minutes"
    ours "$REF_BASE.tmp" "$2" || return 1
    for e in png pfm json log; do mv "$REF_BASE.tmp.$e" "$REF_BASE.$e"; done
    echo "$WALL" >"$REF_BASE.wall"
    REF_NOTE="rendered now"
}
# The references, cached.
if cached_ref ours "$OURS_REF_OPTS" "$OURS_REF_LABEL"; then
    ours_ref=$REF_BASE
    ours_ref_note=$REF_NOTE
else
    ok=0
    status=1
fi
spec_ref=""
if cached_ref spec "$SPEC_REF_OPTS" "$SPEC_REF_LABEL"; then
    spec_ref=$REF_BASE
    spec_ref_note=$REF_NOTE
else
    status=1
fi

if [ "$ok" = 1 ]; then
    i=0
    for lv in "${OURS_LEVELS[@]}"; do
        label=${lv%%|*}
        lopts=${lv#*|}
        base=$RUN/ours-$i
        i=$((i + 1))
        log "photosplat-ref: $label"
        ours "$base" "$lopts" || { status=1; continue; }
        c_png=$("$CMP" "$base.png" "$ours_ref.png")
        c_lin=$("$CMP" "$base.pfm" "$ours_ref.pfm")
        rows+=("photosplat-ref|$label|$WALL|$(fmt %.2f "$(json maps_seconds "$base.json")")|$(fmt %.2f "$(json render_seconds "$base.json")")|$(fmt %.3g "$(field relmse "$c_png")")|$(fmt %.3g "$(field relmse "$c_lin")")|$(fmt %.2f "$(field psnr "$c_png")")")
        # The back wall's band-pass energy (scripts/wall-highpass.py): spots or blotches.
        hp_rows+=("$label|$(python3 scripts/wall-highpass.py "$base.pfm" | sed -n 's/^highpass=\([^ ]*\).*/\1/p')|$WALL|$(fmt %.3g "$(field relmse "$c_png")")|$(fmt %.3g "$(field relmse "$c_lin")")")
    done
    # The specular term at the default settings against its own reference.
    if [ -n "$spec_ref" ]; then
        log "photosplat-ref: the default's specular term"
        if ours "$RUN/ours-spec" "--component specular"; then
            c_spec=$("$CMP" "$RUN/ours-spec.pfm" "$spec_ref.pfm")
            spec_row="$WALL|$(field relmse "$c_spec")"
        fi
    fi
fi
hp_ref=$(python3 scripts/wall-highpass.py "$ours_ref.pfm" 2>/dev/null | sed -n 's/^highpass=\([^ ]*\).*/\1/p')

# ---- POV-Ray ------------------------------------------------------------------
pov_version=""
if [ "$have_pov" = 1 ]; then
    pov_version=$(povray --version 2>&1 | sed -n 's/^\(POV-Ray [0-9][^ ]*\).*/\1/p' | head -1)
    pov_key=$(hash_of "$POV" "$(command -v povray)" <(echo "$SIZE $EXPOSURE $POV_REF_OPTS"))
    pov_ref=$CACHE/pov-$SIZE-$pov_key
    prune "pov-$SIZE" "$pov_key"
    pov_ok=1
    if [ -s "$pov_ref.png" ] && [ -s "$pov_ref.wall" ]; then
        pov_ref_note="cached"
    else
        log "POV-Ray reference ($POV_REF_LABEL), a few minutes"
        if povr "$pov_ref-tmp" "$POV_REF_OPTS"; then
            mv "$pov_ref-tmp.png" "$pov_ref.png"
            mv "$pov_ref-tmp.log" "$pov_ref.log"
            echo "$WALL" >"$pov_ref.wall"
            pov_ref_note="rendered now"
        else
            pov_ok=0
            status=1
        fi
    fi
    if [ "$pov_ok" = 1 ]; then
        i=0
        for lv in "${POV_LEVELS[@]}"; do
            label=${lv%%|*}
            lopts=${lv#*|}
            base=$RUN/pov-$i
            i=$((i + 1))
            log "POV-Ray: $label"
            povr "$base" "$lopts" || { status=1; continue; }
            c_png=$("$CMP" "$base.png" "$pov_ref.png")
            rows+=("POV-Ray|$label|$WALL|$PREPASS|$(fmt %.2f "$TRACE")|$(fmt %.3g "$(field relmse "$c_png")")|-|$(fmt %.2f "$(field psnr "$c_png")")")
        done
    fi
fi

# ---- equal-error ratio ------------------------------------------------------------
# For each photosplat-ref row: POV-Ray's wall seconds to reach the same PNG
# relMSE, and ours / that. POV-Ray's error is not monotone in its settings
# (radiosity interpolation differs from run to run), so only its Pareto front
# counts: the levels, fastest first, that beat every faster level's error.
# Between two front levels log seconds is interpolated in log error; beyond
# the front the nearest level is given, marked < or >.
ratio_rows=$(printf '%s\n' "${rows[@]}" | awk -F'|' '
    $1 == "POV-Ray" && $6 + 0 > 0 { n++; pt[n] = $3 + 0; pe[n] = $6 + 0 }
    $1 == "photosplat-ref" { m++; line[m] = $0; ot[m] = $3 + 0; oe[m] = $6 + 0 }
    END {
        # sort by seconds (insertion sort), then keep the front
        for (i = 2; i <= n; i++)
            for (k = i; k > 1 && pt[k] < pt[k - 1]; k--) {
                x = pt[k]; pt[k] = pt[k - 1]; pt[k - 1] = x
                x = pe[k]; pe[k] = pe[k - 1]; pe[k - 1] = x
            }
        f = 0
        for (i = 1; i <= n; i++)
            if (f == 0 || pe[i] < fe[f]) { f++; ft[f] = pt[i]; fe[f] = pe[i] }
        for (j = 1; j <= m; j++) {
            if (f == 0 || oe[j] <= 0) { print line[j] "|-|-"; continue }
            for (i = 1; i <= f && fe[i] > oe[j]; i++) ;
            mark = ""
            if (i > f) { t = ft[f]; mark = ">" }      # better than every POV-Ray level
            else if (i == 1) { t = ft[1]; mark = (fe[1] < oe[j] ? "<" : "") } # no worse than the fastest
            else {
                w = (log(oe[j]) - log(fe[i - 1])) / (log(fe[i]) - log(fe[i - 1]))
                t = exp(log(ft[i - 1]) + w * (log(ft[i]) - log(ft[i - 1])))
            }
            printf "%s|%s%.2f|%s%.2f\n", line[j], mark, t, (mark == ">" ? "<" : mark == "<" ? ">" : ""), ot[j] / t
        }
    }')

# ---- the side-by-side picture and the cross-renderer check -------------------------------------
cross=""
if [ "$have_pov" = 1 ] && [ -s "${pov_ref:-/nonexistent}.png" ] && [ -s "$ours_ref.png" ]; then
    convert "$ours_ref.png" "$pov_ref.png" \
        \( "$ours_ref.png" "$pov_ref.png" -compose difference -composite -evaluate multiply 4 \) \
        +append "$OUT/ref-vs-povray.tmp.png" && mv "$OUT/ref-vs-povray.tmp.png" "$OUT/ref-vs-povray.png"
    cross=$("$CMP" "$ours_ref.png" "$pov_ref.png")
fi

# ---- report -------------------------------------------------------------------------------------
cpu=$(sed -n 's/^model name[^:]*: *//p' /proc/cpuinfo 2>/dev/null | head -1)
{
    echo "## photosplat-ref against POV-Ray: seconds against error"
    echo
    echo "Scene \`$SCN\` (POV-Ray: \`$POV\`), ${SIZE}x${SIZE}, $THREADS threads, exposure $EXPOSURE;"
    echo "$(nproc) cores of ${cpu:-an unknown CPU}; $(date -u +%Y-%m-%dT%H:%MZ); ${pov_version:-POV-Ray not run}."
    echo "Load average ${load_start:-?} at the start, $(cut -d' ' -f1 /proc/loadavg 2>/dev/null) at the end (above $THREADS, other work shared the cores: timings slower and noisier)."
    echo
    echo "Error: relMSE = mean (a-b)^2/(b^2+0.01) of the 8-bit sRGB PNGs (both renderers alike), each"
    echo "against its own much longer run; photosplat-ref's linear (PFM) relMSE next to it."
    echo "Prepass: photosplat-ref's photon maps + irradiance cache (maps_seconds); POV-Ray's photon"
    echo "shooting + radiosity pretrace. Render: photosplat-ref's render_seconds; POV-Ray's trace time."
    echo "POV-Ray s at equal error: log-log interpolated along the Pareto front of POV-Ray's levels (< or >: beyond it)."
    echo
    echo "References: photosplat-ref $OURS_REF_LABEL ($(cat "$ours_ref.wall" 2>/dev/null || echo '?') s, ${ours_ref_note:-failed});"
    if [ "$have_pov" = 1 ]; then
        echo "POV-Ray $POV_REF_LABEL ($(cat "$pov_ref.wall" 2>/dev/null || echo '?') s, ${pov_ref_note:-failed})."
    fi
    if [ -n "$cross" ]; then
        echo "The two references against each other (POV-Ray as B): $cross"
    fi
    echo
    echo "| renderer | settings | wall s | prepass s | render s | relMSE (PNG) | relMSE (linear) | PSNR dB (PNG) | POV-Ray s at equal error | ours / POV-Ray |"
    echo "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    while IFS='|' read -r r l w p re e el ps pt ra; do
        [ "$r" = "photosplat-ref" ] || continue
        echo "| $r | $l | $w | $p | $re | $e | $el | $ps | $pt | $ra |"
    done <<<"$ratio_rows"
    for row in "${rows[@]}"; do
        IFS='|' read -r r l w p re e el ps <<<"$row"
        [ "$r" = "POV-Ray" ] || continue
        echo "| $r | $l | $w | $p | $re | $e | $el | $ps | | |"
    done
    echo
    echo "### The goals (issue 21)"
    echo
    echo "Back wall band-pass energy (\`scripts/wall-highpass.py\`: mean (box3 - box17)^2 / mean^2 of the luminance"
    echo "above the spheres; the converged reference's own noise: ${hp_ref:-?}):"
    echo
    echo "| settings | wall s | relMSE (PNG) | relMSE (linear) | back-wall band-pass | goal |"
    echo "| --- | ---: | ---: | ---: | ---: | --- |"
    for row in "${hp_rows[@]}"; do
        IFS='|' read -r l h w e el <<<"$row"
        goal=""
        case "$l" in
        "default (default)") goal="$(awk -v w="$w" -v g=$GOAL_DEFAULT_S -v e="$e" -v ge=$GOAL_WHOLE 'BEGIN { printf "%s s <= %d: %s; relMSE %s <= %s: %s", w, g, (w <= g ? "met" : "MISSED"), e, ge, (e <= ge ? "met" : "MISSED") }')" ;;
        final) goal="$(awk -v w="$w" -v g=$GOAL_FINAL_S 'BEGIN { printf "%s s <= %d: %s", w, g, (w <= g ? "met" : "MISSED") }')" ;;
        esac
        echo "| $l | $w | $e | $el | $h | $goal |"
    done
    if [ -n "$spec_row" ]; then
        IFS='|' read -r w e <<<"$spec_row"
        echo
        echo "The specular term at the default settings: relMSE $(fmt %.3g "$e") (linear) against $SPEC_REF_LABEL" \
            "($(cat "$spec_ref.wall" 2>/dev/null || echo '?') s, ${spec_ref_note:-failed}); goal $GOAL_SPECULAR:" \
            "$(awk -v e="$e" -v g=$GOAL_SPECULAR 'BEGIN { print (e <= g ? "met" : "MISSED") }'); $w s."
    fi
    def=$(grep '(default)' <<<"$ratio_rows" | head -1)
    if [ -n "$def" ] && [ "$have_pov" = 1 ]; then
        IFS='|' read -r r l w p re e el ps pt ra <<<"$def"
        echo
        echo "At the README's default settings ($l): ours $w s, POV-Ray $pt s at the same error (relMSE $e): ours / POV-Ray = $ra."
    fi
} >"$OUT/ref.md.tmp"
{
    echo "renderer,settings,wall_s,prepass_s,render_s,relmse_png,relmse_linear,psnr_png,pov_s_equal_error,ours_over_pov"
    while IFS='|' read -r r l w p re e el ps pt ra; do
        [ "$r" = "photosplat-ref" ] || continue
        echo "$r,\"$l\",$w,$p,$re,$e,$el,$ps,$pt,$ra"
    done <<<"$ratio_rows"
    for row in "${rows[@]}"; do
        IFS='|' read -r r l w p re e el ps <<<"$row"
        [ "$r" = "POV-Ray" ] || continue
        echo "$r,\"$l\",$w,$p,$re,$e,,$ps,,"
    done
} >"$OUT/ref.csv.tmp"
mv "$OUT/ref.md.tmp" "$OUT/ref.md"
mv "$OUT/ref.csv.tmp" "$OUT/ref.csv"
cat "$OUT/ref.md"
echo
echo "wrote $OUT/ref.md, $OUT/ref.csv$([ -s "$OUT/ref-vs-povray.png" ] && echo ", $OUT/ref-vs-povray.png (ours | POV-Ray | |difference| x4)") in $(($(date +%s) - t_start)) s"
exit $status
