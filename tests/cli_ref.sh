#!/usr/bin/env bash
# cli_ref.sh BIN_DIR: photosplat-ref --photons-only from the outside: options,
# the --stats keys of the contract, the --dump-photons format, byte-identical
# dumps across thread counts, the skip list, and bad input.
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
ref=$bin/photosplat-ref
scene=data/scenes/cornell-caustic.scn
small=(--caustic-photons 20000 --global-photons 5000)

expect_success "--help" "$ref" --help
expect_match "--help text" "$cli_out" '^usage: photosplat-ref SCENE'
expect_usage_error "no arguments" "$ref"
expect_usage_error "unknown option" "$ref" "$scene" --photons-only --frobnicate
expect_usage_error "nothing to write" "$ref" "$scene"
expect_match "says so" "$cli_err" 'nothing to write'
expect_usage_error "bad component" "$ref" "$scene" -o "$cli_tmp/x.png" --component glow
expect_usage_error "bad kernel" "$ref" "$scene" -o "$cli_tmp/x.png" --kernel triangle
expect_usage_error "zero spp" "$ref" "$scene" -o "$cli_tmp/x.png" --spp 0
expect_usage_error "bad size" "$ref" "$scene" -o "$cli_tmp/x.png" --size 0x10
expect_usage_error "unwritable png" "$ref" "$scene" -o /nonexistent/dir/x.png --size 8x8 --spp 1 "${small[@]}"
[ ! -e "$cli_tmp/x.png" ] && ok || bad "a failed run left x.png behind"
expect_usage_error "negative photons" "$ref" "$scene" --photons-only --caustic-photons -1
expect_usage_error "zero threads" "$ref" "$scene" --photons-only --threads 0
expect_usage_error "bad seed" "$ref" "$scene" --photons-only --seed 1.5
expect_usage_error "bad cones value" "$ref" "$scene" --photons-only --caustic-cones maybe
expect_usage_error "missing scene" "$ref" tests/data/no-such.scn --photons-only
bad_scene=$(ls tests/data/bad/*.scn | head -1)
expect_usage_error "malformed scene" "$ref" "$bad_scene" --photons-only
expect_usage_error "unwritable dump" "$ref" "$scene" --photons-only "${small[@]}" --dump-photons /nonexistent/dir/d.txt
expect_usage_error "unwritable stats" "$ref" "$scene" --photons-only "${small[@]}" --stats /nonexistent/dir/s.json

# The tracer alone: dump and stats.
expect_success "photons-only" "$ref" "$scene" --photons-only "${small[@]}" --threads 1 \
    --dump-photons "$cli_tmp/t1.txt" --stats "$cli_tmp/s1.json"
expect_match "summary line" "$cli_out" '^caustic: 20000 emitted, [0-9]+ stored; global: 5000 emitted'
for key in emitted_caustic emitted_global stored_caustic stored_global trace_seconds splat_seconds frames \
    photons_per_second rays_traced rays_per_second skipped; do
    grep -q "\"$key\":" "$cli_tmp/s1.json" && ok || bad "stats lacks $key"
done
grep -q '"emitted_caustic": 20000,' "$cli_tmp/s1.json" && ok || bad "emitted_caustic is not 20000"
grep -q '"skipped": \[\]' "$cli_tmp/s1.json" && ok || bad "the default scene skips something: $(cat "$cli_tmp/s1.json")"
if command -v python3 >/dev/null; then
    python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["rays_traced"] > 0' "$cli_tmp/s1.json" \
        && ok || bad "stats is not valid JSON with rays"
fi
stat() { sed -nE "s/.*\"$1\": ([0-9]+).*/\1/p" "$2"; }
stored=$(($(stat stored_caustic "$cli_tmp/s1.json") + $(stat stored_global "$cli_tmp/s1.json")))
lines=$(wc -l <"$cli_tmp/t1.txt")
[ "$lines" -eq "$stored" ] && ok || bad "dump has $lines lines, stats say $stored stored"
# Each line: map and 12 numbers.
awk 'NF != 13 || ($1 != "caustic" && $1 != "global") { bad = 1 } END { exit bad }' "$cli_tmp/t1.txt" \
    && ok || bad "dump lines are not 'map x y z r g b dx dy dz nx ny nz'"
grep -q '^caustic ' "$cli_tmp/t1.txt" && grep -q '^global ' "$cli_tmp/t1.txt" && ok || bad "dump lacks a map"

# Thread count never changes the photons.
expect_success "two threads" "$ref" "$scene" --photons-only "${small[@]}" --threads 2 --dump-photons "$cli_tmp/t2.txt"
cmp -s "$cli_tmp/t1.txt" "$cli_tmp/t2.txt" && ok || bad "dumps differ between 1 and 2 threads"
expect_success "other seed" "$ref" "$scene" --photons-only "${small[@]}" --seed 99 --dump-photons "$cli_tmp/t3.txt"
cmp -s "$cli_tmp/t1.txt" "$cli_tmp/t3.txt" && bad "another seed gave the same photons" || ok

# Skips: no specular object, and zero photons asked for.
expect_success "diffuse box" "$ref" tests/data/good/diffuse-box.scn --photons-only --stats "$cli_tmp/s4.json"
grep -q '"pass": "caustic", "reason": "no specular' "$cli_tmp/s4.json" && ok || bad "no caustic skip: $(cat "$cli_tmp/s4.json")"
grep -q '"emitted_caustic": 0,' "$cli_tmp/s4.json" && ok || bad "caustic photons emitted in a diffuse box"
grep -q '"emitted_global": 2000,' "$cli_tmp/s4.json" && ok || bad "the scene's photon count was not used"
expect_success "zero global" "$ref" "$scene" --photons-only --caustic-photons 1000 --global-photons 0 \
    --stats "$cli_tmp/s5.json"
grep -q '"pass": "global", "reason": "0 photons requested"' "$cli_tmp/s5.json" && ok || bad "no skip for 0 photons"

# The image: PNG and PFM of the right size, every component.
expect_success "render" "$ref" "$scene" -o "$cli_tmp/r.png" --hdr "$cli_tmp/r.pfm" --size 32x24 --spp 1 \
    --gather 4 "${small[@]}" --stats "$cli_tmp/r.json"
[ "$(head -c 8 "$cli_tmp/r.png" | od -An -tx1 | tr -d ' ')" = 89504e470d0a1a0a ] && ok || bad "r.png is not a PNG"
[ "$(head -2 "$cli_tmp/r.pfm" | tr '\n' ' ')" = "PF 32 24 " ] && ok || bad "r.pfm is not a 32x24 PFM"
grep -q '"render_seconds":' "$cli_tmp/r.json" && ok || bad "stats lack render_seconds"
for c in all direct caustic indirect specular; do
    expect_success "component $c" "$ref" "$scene" --hdr "$cli_tmp/c-$c.pfm" --size 16x16 --spp 1 --gather 2 \
        --component "$c" "${small[@]}"
done
# Thread count never changes the image.
expect_success "render 1 thread" "$ref" "$scene" --hdr "$cli_tmp/t1.pfm" --size 16x16 --spp 1 --gather 2 \
    --cache 0 --threads 1 "${small[@]}"
expect_success "render 2 threads" "$ref" "$scene" --hdr "$cli_tmp/t2.pfm" --size 16x16 --spp 1 --gather 2 \
    --cache 0 --threads 2 "${small[@]}"
cmp -s "$cli_tmp/t1.pfm" "$cli_tmp/t2.pfm" && ok || bad "images differ between 1 and 2 threads"
# ... nor with the irradiance cache, whose records are made in any order.
for n in 1 2; do
    expect_success "cache, $n threads" "$ref" "$scene" --hdr "$cli_tmp/k$n.pfm" --size 16x16 --spp 1 --gather 2 \
        --cache 1 --cache-rays 16 --threads $n "${small[@]}"
done
cmp -s "$cli_tmp/k1.pfm" "$cli_tmp/k2.pfm" && ok || bad "cached images differ between 1 and 2 threads"
cmp -s "$cli_tmp/k1.pfm" "$cli_tmp/t1.pfm" && bad "the cache changed nothing" || ok
expect_usage_error "negative cache" "$ref" "$scene" -o "$cli_tmp/x.png" --cache -1
# Quality presets set their options together; options given explicitly win.
expect_usage_error "bad quality" "$ref" "$scene" -o "$cli_tmp/x.png" --quality best
expect_usage_error "bad filter" "$ref" "$scene" -o "$cli_tmp/x.png" --filter lanczos
expect_success "final, spp 1" "$ref" "$scene" --hdr "$cli_tmp/q.pfm" --size 16x16 --quality final --spp 1 \
    --caustic-photons 20000 --stats "$cli_tmp/q.json"
grep -q '"spp": 1,' "$cli_tmp/q.json" && ok || bad "--spp did not win over --quality final"
grep -q '"cache_rays": 2048,' "$cli_tmp/q.json" && ok || bad "--quality final did not set --cache-rays"
grep -q '"emitted_caustic": 20000,' "$cli_tmp/q.json" && ok || bad "--caustic-photons did not win over the preset"
grep -q '"emitted_global": 100000,' "$cli_tmp/q.json" && ok || bad "--quality final did not double the global photons"
expect_success "draft" "$ref" "$scene" --hdr "$cli_tmp/d.pfm" --size 16x16 --quality draft --stats "$cli_tmp/d.json"
grep -q '"spp": 1,' "$cli_tmp/d.json" && grep -q '"gather": 8,' "$cli_tmp/d.json" && ok || bad "--quality draft: $(cat "$cli_tmp/d.json")"
# The filters: box is each pixel's own samples; the wider ones differ, same bytes for any thread count.
for f in box mitchell gaussian; do
    for n in 1 2; do
        expect_success "filter $f, $n threads" "$ref" "$scene" --hdr "$cli_tmp/f-$f-$n.pfm" --size 24x24 --spp 2 \
            --gather 2 --cache-rays 16 --filter $f --threads $n "${small[@]}"
    done
    cmp -s "$cli_tmp/f-$f-1.pfm" "$cli_tmp/f-$f-2.pfm" && ok || bad "filter $f: images differ between 1 and 2 threads"
done
cmp -s "$cli_tmp/f-box-1.pfm" "$cli_tmp/f-mitchell-1.pfm" && bad "the Mitchell filter changed nothing" || ok

# The golden image (scripts/regen-golden.sh remakes it, on purpose only). The
# renderer is deterministic, so the tolerance only absorbs compiler-level
# rounding; it is far tighter than the noise: another seed must fail it.
golden=tests/data/golden/cornell-caustic-ref
# shellcheck disable=SC2046
expect_success "golden render" "$ref" $(cut -d" " -f2- "$golden.args") --hdr "$cli_tmp/g.pfm"
# shellcheck disable=SC2046
expect_success "other seed" "$ref" $(cut -d" " -f2- "$golden.args") --seed 2 --hdr "$cli_tmp/g2.pfm"
within_golden() { # image: relMSE below 1e-4 and means within 0.2 %
    "$bin/photosplat-compare" "$1" "$golden.pfm" |
        awk '{for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] } }
             END { exit !(v["relmse"] < 1e-4 && (v["mean_a"] - v["mean_b"])^2 < (0.002 * v["mean_b"])^2) }'
}
within_golden "$cli_tmp/g.pfm" && ok || bad "the default scene's image moved from the golden one: $("$bin/photosplat-compare" "$cli_tmp/g.pfm" "$golden.pfm")"
within_golden "$cli_tmp/g2.pfm" && bad "the golden tolerance passes another seed's noise" || ok

cli_summary
