#!/usr/bin/env bash
# cli_snap.sh BIN_DIR: photosplat-snap from the outside: options and bad
# input, golden pictures of the default scene, the same bytes for any number
# of llvmpipe threads, progressive mode, the contract's --stats keys, and the
# 8-bit precision stress (thesis 5.1): a caustic of millions of faint photons
# that plain 8-bit loses, error diffusion keeps and the counter stops.
# run-tests: alone (it times what it runs, or opens windows on Xvfb)
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
snap=$bin/photosplat-snap
scene=data/scenes/cornell-caustic.scn
mirror=tests/data/good/mirror-caustic.scn
small=(--size 48x48 --caustic-photons 20000 --global-photons 5000)
# Image means from photosplat-compare's report of an image against itself.
mean_of() { "$bin/photosplat-compare" "$1" "$1" | sed -n 's/.*mean_a=\([^ ]*\).*/\1/p'; }
# awk_true EXPR: exit status 0 when the awk expression holds.
awk_true() { awk "BEGIN { exit !($1) }"; }

expect_success "--help" "$snap" --help
expect_match "--help text" "$cli_out" '^usage: photosplat-snap SCENE'
expect_usage_error "no arguments" "$snap"
expect_usage_error "nothing to write" "$snap" "$scene"
expect_usage_error "unknown option" "$snap" "$scene" -o "$cli_tmp/x.png" --frobnicate
expect_usage_error "bad splat" "$snap" "$scene" -o "$cli_tmp/x.png" --splat quads
expect_usage_error "bad kernel" "$snap" "$scene" -o "$cli_tmp/x.png" --kernel triangle
expect_usage_error "bad layer" "$snap" "$scene" -o "$cli_tmp/x.png" --layers direct,glow
expect_usage_error "empty layer" "$snap" "$scene" -o "$cli_tmp/x.png" --layers direct,
expect_usage_error "bad depth" "$snap" "$scene" -o "$cli_tmp/x.png" --color-depth 16
expect_usage_error "bad bake" "$snap" "$scene" -o "$cli_tmp/x.png" --bake maybe
expect_usage_error "bad precision" "$snap" "$scene" -o "$cli_tmp/x.png" --precision dither
expect_usage_error "zero tau" "$snap" "$scene" -o "$cli_tmp/x.png" --tau 0
expect_usage_error "bad size" "$snap" "$scene" -o "$cli_tmp/x.png" --size 0x4
expect_usage_error "missing scene" "$snap" "$cli_tmp/none.scn" -o "$cli_tmp/x.png"
expect_match "names the file" "$cli_err" 'none\.scn'
expect_usage_error "bad scene" "$snap" tests/data/bad/$(ls tests/data/bad | head -1) -o "$cli_tmp/x.png"
expect_usage_error "unwritable png" "$snap" "$scene" "${small[@]}" -o /nonexistent/dir/x.png
[ ! -e "$cli_tmp/x.png" ] && ok || bad "a failed run left x.png behind"

# A run: PNG and PFM of the right size, the contract's stats keys.
expect_success "snapshot" "$snap" "$scene" "${small[@]}" -o "$cli_tmp/s.png" --hdr "$cli_tmp/s.pfm" \
    --stats "$cli_tmp/s.json" --dump-photons "$cli_tmp/s.txt"
[ "$(head -c 8 "$cli_tmp/s.png" | od -An -tx1 | tr -d ' ')" = 89504e470d0a1a0a ] && ok || bad "s.png is not a PNG"
[ "$(head -2 "$cli_tmp/s.pfm" | tr '\n' ' ')" = "PF 48 48 " ] && ok || bad "s.pfm is not a 48x48 PFM"
for key in emitted_caustic emitted_global stored_caustic stored_global trace_seconds splat_seconds frames \
    photons_per_second rays_traced rays_per_second skipped; do
    grep -q "\"$key\":" "$cli_tmp/s.json" && ok || bad "stats lack $key"
done
grep -q '"emitted_caustic": 20000,' "$cli_tmp/s.json" && ok || bad "not 20000 caustic photons"
grep -q '"luminous_flux_lm": 68300[,.]' "$cli_tmp/s.json" && ok ||
    bad "stats lack the lights' lumens (100 W a channel: 683 lm/W x Y 100 = 68300 lm)"

# Illuminance: a one-channel PFM of lux and its false-colour picture (the
# closed forms are test_gl_illuminance's); bad paths refused before any work.
expect_success "illuminance" "$snap" "$scene" "${small[@]}" --illuminance "$cli_tmp/lux.pfm" \
    --false-color "$cli_tmp/lux.png"
[ "$(head -2 "$cli_tmp/lux.pfm" | tr '\n' ' ')" = "Pf 48 48 " ] && ok || bad "lux.pfm is not a one-channel 48x48 PFM"
[ "$(head -c 8 "$cli_tmp/lux.png" | od -An -tx1 | tr -d ' ')" = 89504e470d0a1a0a ] && ok || bad "lux.png is not a PNG"
expect_success "OpenEXR" "$snap" "$scene" "${small[@]}" --hdr "$cli_tmp/s.exr"
[ "$(head -c 4 "$cli_tmp/s.exr" | od -An -tx1 | tr -d ' ')" = 762f3101 ] && ok || bad "s.exr is not OpenEXR"
[[ $("$bin/photosplat-compare" "$cli_tmp/s.exr" "$cli_tmp/s.pfm") == rmse=0\ * ]] && ok || bad "the EXR is not the PFM's picture"
expect_usage_error "unwritable illuminance" "$snap" "$scene" "${small[@]}" --illuminance /nonexistent/dir/l.pfm
[ "$(grep -c '^caustic ' "$cli_tmp/s.txt")" = "$(sed -n 's/.*"stored_caustic": \([0-9]*\).*/\1/p' "$cli_tmp/s.json")" ] &&
    ok || bad "the dump and the stats disagree on the caustic photons"

# Layers: one that is off is not traced and says so; the others still occlude.
expect_success "direct only" "$snap" "$scene" "${small[@]}" --layers direct -o "$cli_tmp/d.png" --stats "$cli_tmp/d.json"
grep -q '"pass": "caustic", "reason": "layer not shown (--layers)"' "$cli_tmp/d.json" && ok || bad "no skip for the caustic layer"
grep -q '"emitted_caustic": 0,' "$cli_tmp/d.json" && ok || bad "a hidden layer's photons were traced"

# Golden pictures (scripts/regen-golden.sh remakes them, on purpose only).
# llvmpipe is deterministic, so the tolerance only absorbs rounding: an RMSE
# of 2 codes in 255 on the stored values.
# (specular: --layers direct,specular, the direct light seen in the mirror and
# through the glass.)
for mode in triangles points specular; do
    golden=tests/data/golden/cornell-caustic-snap-$mode
    # shellcheck disable=SC2046
    expect_success "golden $mode" "$snap" $(cut -d" " -f2- "$golden.args") -o "$cli_tmp/g-$mode.png"
    rmse=$("$bin/photosplat-compare" "$cli_tmp/g-$mode.png" "$golden.png" | sed -n 's/^rmse=\([^ ]*\).*/\1/p')
    awk_true "$rmse < 2.0 / 255" && ok || bad "$mode picture moved from the golden one: rmse $rmse"
done
# ... and the tolerance is tighter than the difference between the modes.
rmse=$("$bin/photosplat-compare" "$cli_tmp/g-points.png" "$cli_tmp/g-triangles.png" | sed -n 's/^rmse=\([^ ]*\).*/\1/p')
awk_true "$rmse > 4.0 / 255" && ok || bad "points and triangles are within the golden tolerance of each other"

# The same bytes for any number of llvmpipe threads.
for n in 1 2 3; do
    expect_success "LP_NUM_THREADS=$n" env LP_NUM_THREADS=$n "$snap" "$scene" "${small[@]}" -o "$cli_tmp/lp$n.png"
done
cmp -s "$cli_tmp/lp1.png" "$cli_tmp/lp2.png" && cmp -s "$cli_tmp/lp1.png" "$cli_tmp/lp3.png" && ok ||
    bad "the picture depends on LP_NUM_THREADS"

# ... and whether llvmpipe optimises its programs: snap leaves its passes out
# (GALLIVM_PERF=nopt, platform_osmesa.c) unless the user set GALLIVM_PERF,
# here empty: Mesa's defaults. Every layer of the design room (its specular
# layer too), 8 bits and float, triangles and sprites (their own programs).
for args in "--splat triangles --color-depth 8" "--splat sprites --color-depth float"; do
    for opt in default passes; do
        if [ $opt = default ]; then e=(env -u GALLIVM_PERF); else e=(env GALLIVM_PERF=); fi
        expect_success "llvmpipe $opt, $args" "${e[@]}" "$snap" data/scenes/design-room.scn "${small[@]}" $args \
            --hdr "$cli_tmp/opt-$opt.pfm" --hdr-layers "$cli_tmp/opt-$opt"
    done
    for f in opt-default.pfm opt-default-direct.pfm opt-default-caustic.pfm opt-default-global.pfm \
        opt-default-specular.pfm; do
        cmp -s "$cli_tmp/$f" "$cli_tmp/${f/default/passes}" && ok ||
            bad "$f ($args) differs with llvmpipe's optimisation passes"
    done
done

# Progressive mode: several refreshes, photons up to the cap at most.
expect_success "progressive" "$snap" "$scene" --size 32x32 --time 0.6 --tau 0.1 --caustic-photons 400000 \
    --global-photons 100000 -o "$cli_tmp/p.png" --stats "$cli_tmp/p.json"
frames=$(sed -n 's/.*"frames": \([0-9]*\).*/\1/p' "$cli_tmp/p.json")
awk_true "$frames >= 2" && ok || bad "progressive mode refreshed $frames times in 0.6 s at tau 0.1"
grep -q '"first_frame_seconds":' "$cli_tmp/p.json" && ok || bad "no first_frame_seconds"
# Float checkpoints: the tracer waits for the first picture (which then has
# every core), so it comes at once, not at tau (here 1.5 s; before, it
# waited for it).
expect_success "float first picture at once" "$snap" "$scene" --size 32x32 --color-depth float --time 1.6 --tau 1.5 \
    --checkpoints 1.6 --checkpoint-prefix "$cli_tmp/fa" --stats "$cli_tmp/fa.json"
first=$(sed -n 's/.*"first_frame_seconds": \([0-9.e+-]*\).*/\1/p' "$cli_tmp/fa.json")
# Under the sanitizers a loaded make test put it at 1.26 s (0.75-0.89 s run
# alone): still before tau, which a wait for it would not be.
if [[ $bin == *asan* ]]; then first_by=1.4; else first_by=1.0; fi
awk_true "$first < $first_by" && ok || bad "float checkpoints: the first picture came at $first s, after tau"
# Float checkpoints: a refresh that would find nothing new waits for the
# tracer's next batch or its time instead (snap_main.c, await_photons). Before,
# the frame planned at once for a checkpoint drew nothing, ended before it and
# was planned again: 685-4961 refreshes in runs like these, now 9-14.
most=0
for run in 1 2 3; do
    expect_success "float waits for photons ($run)" "$snap" "$scene" --size 128x128 --splat points --color-depth float \
        --caustic-photons 8000000 --global-photons 2000000 --time 0.5 --checkpoints 0.05,0.1,0.2,0.5 \
        --checkpoint-prefix "$cli_tmp/fw" --stats "$cli_tmp/fw.json" -o "$cli_tmp/fw.png"
    frames=$(sed -n 's/.*"frames": \([0-9]*\).*/\1/p' "$cli_tmp/fw.json")
    awk_true "$frames > $most" && most=$frames
done
awk_true "$most <= 200" && ok || bad "float checkpoints: a run refreshed $most times in 0.5 s"
# Progressive in float draws only new photons into layers kept between
# refreshes (as the window): at the caps the same picture as drawing them all
# at once, but for the order of float additions.
expect_success "progressive float" "$snap" "$scene" "${small[@]}" --color-depth float --time 30 --tau 0.05 \
    --hdr "$cli_tmp/pf.pfm" --stats "$cli_tmp/pf.json"
expect_success "fixed float" "$snap" "$scene" "${small[@]}" --color-depth float --hdr "$cli_tmp/ff.pfm"
rel=$("$bin/photosplat-compare" "$cli_tmp/pf.pfm" "$cli_tmp/ff.pfm" | sed -n 's/.*relmse=\([^ ]*\).*/\1/p')
awk_true "$rel < 1e-8" && ok || bad "progressive float layers differ from one whole frame: relMSE $rel"

# The precision stress: a caustic of many faint photons, with an exposure
# that keeps each photon under half a code of the 8-bit buffer, in every
# splat mode (the accurate splats draw an 8-bit buffer's kernel as a halftone,
# so that each fragment adds the photon's code or nothing: preview/splat.h).
# The release build takes 2 million photons (triangles: diffusion within 0.2 %
# of float; with 5 million, as faint, 0.3 %, in 13 s against 6); the
# sanitizer build a quarter, as faint, for points; for the textured splats
# half at 96², since the halftone's dither leaves about a percent of noise on
# the mean of an image of so few codes (64² at exposure 0.2: +2.5 % for
# sprites).
for mode in points triangles sprites; do
    size=()
    if [[ $bin != *asan* ]]; then
        n=2000000 exposure=0.8
    elif [ $mode = points ]; then
        n=500000 exposure=0.2
    else
        n=1000000 exposure=0.4 size=(--size 96x96)
    fi
    stress=("$mirror" "${size[@]}" --layers caustic --splat $mode --caustic-photons $n --exposure $exposure)
    expect_success "stress $mode float" "$snap" "${stress[@]}" --color-depth float --hdr "$cli_tmp/f.pfm"
    expect_success "stress $mode none" "$snap" "${stress[@]}" --precision none --hdr "$cli_tmp/n.pfm"
    expect_success "stress $mode diffusion" "$snap" "${stress[@]}" --precision diffusion --hdr "$cli_tmp/e.pfm"
    mf=$(mean_of "$cli_tmp/f.pfm") mn=$(mean_of "$cli_tmp/n.pfm") me=$(mean_of "$cli_tmp/e.pfm")
    echo "precision stress, $mode, $n photons: mean radiance float $mf, 8-bit none $mn, 8-bit diffusion $me"
    awk_true "$mf > 0.05" && ok || bad "$mode: the float caustic is dark ($mf)"
    awk_true "$mn < 0.1 * $mf" && ok || bad "$mode: plain 8-bit kept the caustic ($mn of $mf): the stress is not faint enough"
    awk_true "($me - $mf)^2 < (0.02 * $mf)^2" && ok ||
        bad "$mode: error diffusion's mean $me is not within 2 % of the float buffer's $mf"
done
# The counter, shooting progressively, stops once a refresh rounds too much
# away: with points, and with the textured splats, whose halftone makes what
# they lose the colour's rounding alone, which the counter counts.
if [[ $bin == *asan* ]]; then n=500000 exposure=0.2; else n=2000000 exposure=0.8; fi
for mode in points triangles; do
    stress=("$mirror" --layers caustic --splat $mode --caustic-photons $n --exposure $exposure)
    expect_success "stress counter $mode" "$snap" "${stress[@]}" --precision counter --time 60 --tau 0.05 \
        --hdr "$cli_tmp/c.pfm" --stats "$cli_tmp/c.json"
    expect_match "counter says why ($mode)" "$cli_out" 'error counter: stopped shooting at [0-9]+ photons'
    grep -q '"counter_stopped": 1,' "$cli_tmp/c.json" && ok || bad "$mode: stats do not say the counter stopped"
    emitted=$(sed -n 's/.*"emitted_caustic": \([0-9]*\).*/\1/p' "$cli_tmp/c.json")
    awk_true "$emitted < $n" && ok || bad "$mode: the counter let all $emitted photons through"
done
# Checkpoints after the counter stopped get their own frames at their time
# (before, the last picture showed them when the counter stopped: the 2 s
# one at 0.46 s), and the run still ends soon after the last.
expect_success "counter checkpoints" "$snap" "$mirror" --layers caustic --caustic-photons $n --exposure $exposure \
    --precision counter --time 60 --tau 0.05 --checkpoints 0.5,2 --checkpoint-prefix "$cli_tmp/ct" --stats "$cli_tmp/ct.json"
awk -F, 'NR > 1 && ($3 < $2 || $3 > 2 * $2 + 0.5) { print "checkpoint " $2 " s at " $3 " s"; bad = 1 } END { exit bad }' \
    "$cli_tmp/ct.csv" && ok || bad "counter checkpoints: $(cat "$cli_tmp/ct.csv")"
grep -q '"counter_stopped": 1,' "$cli_tmp/ct.json" && ok || bad "counter checkpoints: the counter did not stop"
run_seconds=$(sed -n 's/.*"seconds": \([0-9.]*\).*/\1/p' "$cli_tmp/ct.json")
awk_true "$run_seconds < 10" && ok || bad "counter checkpoints: the run took $run_seconds s"

# --global-layer maps: the global layer as illumination maps. Its picture is
# the splats' within the kernels' difference (mean within 5 %), the same
# bytes for 1 and 2 tracing threads, and progressive refreshes (float
# layers, scaled in the composite) end at one whole frame (scaled in the
# colours) but for float rounding.
expect_usage_error "bad global layer" "$snap" "$scene" -o "$cli_tmp/x.png" --global-layer texels
maps=("$scene" --size 64x64 --caustic-photons 20000 --global-photons 20000 --layers global --color-depth float)
expect_success "maps" "$snap" "${maps[@]}" --global-layer maps --hdr "$cli_tmp/gm1.pfm" --threads 1 \
    --stats "$cli_tmp/gm.json"
grep -q '"global_maps": 1' "$cli_tmp/gm.json" && ok || bad "stats do not say global_maps"
expect_success "maps, 2 threads" "$snap" "${maps[@]}" --global-layer maps --hdr "$cli_tmp/gm2.pfm" --threads 2
cmp -s "$cli_tmp/gm1.pfm" "$cli_tmp/gm2.pfm" && ok || bad "maps: 1 and 2 threads differ"
expect_success "maps, progressive" "$snap" "${maps[@]}" --global-layer maps --hdr "$cli_tmp/gmp.pfm" --time 30 \
    --tau 0.02
rel=$("$bin/photosplat-compare" "$cli_tmp/gmp.pfm" "$cli_tmp/gm1.pfm" | sed -n 's/.*relmse=\([^ ]*\).*/\1/p')
awk_true "$rel < 1e-8" && ok || bad "maps: progressive refreshes differ from one whole frame: relMSE $rel"
expect_success "splats" "$snap" "${maps[@]}" --hdr "$cli_tmp/gs.pfm"
ms=$(mean_of "$cli_tmp/gs.pfm") mm=$(mean_of "$cli_tmp/gm1.pfm")
awk_true "($mm - $ms)^2 < (0.05 * $ms)^2 && $ms > 0.01" && ok || bad "maps' mean $mm is not the splats' $ms"

cli_summary
