#!/usr/bin/env bash
# cli_ies.sh BIN_DIR: IES luminaires and photometric outputs from the outside:
# photosplat-ref --illuminance (one-channel PFM or EXR), --false-color (PNG
# with its legend), --hdr FILE.exr, luminous_flux_lm in --stats; malformed
# LM-63 files refused with their line (exit 2, nothing written); the gallery
# scene in photosplat-info, -ref and -snap.
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
ref=$bin/photosplat-ref
fast=(--size 16x12 --spp 1 --gather 0 --caustic-photons 2000 --global-photons 2000 --threads 2)

scene=$cli_tmp/ies.scn
cat >"$scene" <<SCN
camera eye 0 1 2 target 0 0 0
material floor diffuse albedo 0.5 0.5 0.5
quad corner -5 0 5 edge1 10 0 0 edge2 0 0 -10 material floor
light ies $PWD/data/ies/batwing.ies position 0 2 0 lumens 1200 color 1 0.9 0.8
SCN

expect_success "illuminance, false colour, exr, stats" "$ref" "$scene" "${fast[@]}" --illuminance "$cli_tmp/lux.pfm" \
    --false-color "$cli_tmp/lux.png" --hdr "$cli_tmp/rad.exr" --stats "$cli_tmp/s.json"
[ "$(head -c 11 "$cli_tmp/lux.pfm" 2>/dev/null | tr '\n' ' ')" = "Pf 16 12 -1" ] && ok || bad "lux.pfm is not a 16x12 one-channel PFM"
[ "$(od -An -tx1 -N4 "$cli_tmp/rad.exr" 2>/dev/null | tr -d ' ')" = "762f3101" ] && ok || bad "rad.exr has no OpenEXR magic"
[ "$(od -An -tx1 -N8 "$cli_tmp/lux.png" 2>/dev/null | tr -d ' ')" = "89504e470d0a1a0a" ] && ok || bad "lux.png is no PNG"
# The false-colour picture: the image and its 72-pixel legend (PNG width at byte 16).
[ "$(od -An -tu1 -j16 -N4 "$cli_tmp/lux.png" | awk '{print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4}')" = 88 ] && ok ||
    bad "lux.png is not 16 + 72 pixels wide"
expect_match "stats: lumens" "$(cat "$cli_tmp/s.json")" '"luminous_flux_lm": 1200(\.0+)?[,}]'
expect_success "illuminance as exr, direct only" "$ref" "$scene" "${fast[@]}" --illuminance "$cli_tmp/lux.exr" --component direct
[ "$(od -An -tx1 -N4 "$cli_tmp/lux.exr" 2>/dev/null | tr -d ' ')" = "762f3101" ] && ok || bad "lux.exr has no OpenEXR magic"

# The same run's radiance as PFM and as EXR (float): photosplat-compare reads both, no difference.
expect_success "hdr as pfm" "$ref" "$scene" "${fast[@]}" --hdr "$cli_tmp/rad.pfm"
expect_success "compare exr with pfm" "$bin/photosplat-compare" "$cli_tmp/rad.exr" "$cli_tmp/rad.pfm"
expect_match "exr equals pfm" "$cli_out" '^rmse=0 relmse=0 '

expect_usage_error "illuminance into a missing folder" "$ref" "$scene" "${fast[@]}" --illuminance /nonexistent/dir/l.pfm
expect_usage_error "false colour into a missing folder" "$ref" "$scene" "${fast[@]}" --false-color /nonexistent/dir/l.png

# Malformed LM-63 files: the IES file's line, then the scene's.
for f in tests/data/ies-bad/*.ies; do
    want=$(sed -n 's/^\[_EXPECT\] \([0-9]*\): .*/\1/p' "$f" | head -1)
    printf 'camera eye 0 1 2 target 0 0 0\nlight ies %s position 0 2 0\n' "$PWD/$f" >"$cli_tmp/bad.scn"
    expect_usage_error "bad ies $(basename "$f")" "$ref" "$cli_tmp/bad.scn" "${fast[@]}" --illuminance "$cli_tmp/bad.pfm"
    expect_match "bad ies $(basename "$f") names its line" "$cli_err" "$(basename "$f"):$want: .*\(light ies at .*bad.scn:2\)"
done
[ ! -e "$cli_tmp/bad.pfm" ] && ok || bad "a refused scene left bad.pfm behind"
printf 'camera eye 0 1 2 target 0 0 0\nlight ies %s position 0 2 0\n' "$PWD/data/ies" >"$cli_tmp/dir.scn"
expect_usage_error "an ies 'file' that is a directory" "$ref" "$cli_tmp/dir.scn" --photons-only
expect_match "says so" "$cli_err" 'dir.scn:2: light ies: .*data/ies'

# The bundled gallery.
expect_success "info gallery" "$bin/photosplat-info" data/scenes/gallery.scn
expect_match "info: lumens" "$cli_out" '^lights +7, total power .* W, 12100 lm'
expect_match "info: ies files" "$cli_out" 'downlight-narrow.ies \(LM-63-2002, 19 x 1 angles'
expect_success "ref gallery" "$ref" data/scenes/gallery.scn "${fast[@]}" -o "$cli_tmp/g.png" --false-color "$cli_tmp/gf.png"
if [ -x "$bin/photosplat-snap" ]; then
    expect_success "snap gallery" "$bin/photosplat-snap" data/scenes/gallery.scn -o "$cli_tmp/gs.png" --size 32x24 \
        --caustic-photons 2000 --global-photons 2000
fi
cli_summary
