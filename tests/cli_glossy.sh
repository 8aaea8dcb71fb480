#!/usr/bin/env bash
# cli_glossy.sh BIN_DIR: glossy lobes in the specular layer against the
# reference renderer, on the design room's glossy floor (the pixels whose
# eye ray and its 8 neighbours' meet it, tool_material_mask).
#  - The floor made purely glossy (albedo 0, specular 0.5): what the specular
#    layer adds there (all four layers less direct,caustic: the global
#    splats carry no lobe while the layer shows, so the difference is the
#    layer) against photosplat-ref --component specular, which on a glossy
#    surface seen directly is the lobe's gather (the floor has no albedo, so
#    --component indirect there is 0): the mean within 3 %.
#  - The design room itself, all layers against the whole reference on the
#    floor: the mean within 10 %, relMSE under 0.08 (0.215 before the lobes
#    were the layer's and GL's capped highlight was normalised for its own
#    width).
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
case "$bin" in build/*/bin) tools=${bin%/bin}/tests ;; *) tools=build/release/tests ;; esac
field() { sed -n "s/.*$1=\([^ ]*\).*/\1/p"; }
awk_true() { awk "BEGIN { exit !($1) }"; }
size=128x96
room=data/scenes/design-room.scn
pure=$cli_tmp/pure.scn
sed 's/^material floor .*/material floor glossy albedo 0 0 0 specular 0.5 0.5 0.5 exponent 60/' "$room" >"$pure"
snap() { "$bin/photosplat-snap" "$@" --size $size --color-depth float --threads 2 -o "$cli_tmp/x.png"; }
ref() { "$bin/photosplat-ref" "$@" --size $size --threads 2 -o "$cli_tmp/x.png"; }
mean_on_floor() { "$bin/photosplat-compare" "$1" "$2" --mask "$cli_tmp/floor.pfm"; }

expect_success "floor mask" "$tools/tool_material_mask" "$room" $size floor "$cli_tmp/floor.pfm"
pixels=$(echo "$cli_out" | field pixels)
if awk_true "${pixels:-0} > 3000"; then ok; else bad "floor mask: $pixels pixels"; fi

expect_success "pure glossy: reference specular" ref "$pure" --component specular --hdr "$cli_tmp/ref_spec.pfm"
expect_success "pure glossy: all layers" snap "$pure" --hdr "$cli_tmp/all.pfm"
expect_success "pure glossy: direct,caustic" snap "$pure" --layers direct,caustic --hdr "$cli_tmp/dc.pfm"
all=$(mean_on_floor "$cli_tmp/all.pfm" "$cli_tmp/ref_spec.pfm" | field mean_a)
dc=$(mean_on_floor "$cli_tmp/dc.pfm" "$cli_tmp/ref_spec.pfm" | field mean_a)
want=$(mean_on_floor "$cli_tmp/dc.pfm" "$cli_tmp/ref_spec.pfm" | field mean_b)
echo "pure glossy floor: the specular layer $(awk "BEGIN { print $all - $dc }") against the reference's specular $want"
if awk_true "$want > 0.05 && ($all - $dc) / $want > 0.97 && ($all - $dc) / $want < 1.03"; then ok; else
    bad "pure glossy floor: the layer $all - $dc against $want"
fi

expect_success "design room: reference" ref "$room" --hdr "$cli_tmp/ref_all.pfm"
expect_success "design room: all layers" snap "$room" --hdr "$cli_tmp/room.pfm"
line=$(mean_on_floor "$cli_tmp/room.pfm" "$cli_tmp/ref_all.pfm")
echo "design room floor: $line"
a=$(echo "$line" | field mean_a) b=$(echo "$line" | field mean_b) rel=$(echo "$line" | field relmse)
if awk_true "$a / $b > 0.9 && $a / $b < 1.1 && $rel < 0.08"; then ok; else bad "design room floor: $line"; fi

cli_summary
