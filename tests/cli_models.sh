#!/usr/bin/env bash
# cli_models.sh BIN_DIR: models opened directly and their textures.
# - A quad with a 2x2 checker texture (map_Kd, albedos 0.2 and 0.8) under a
#   point light: the reference's radiance on the two squares within 1 % of
#   albedo E / pi, the preview's (photosplat-snap, both its single colour
#   buffer and its float layers) within 2 %, their ratio 4 (tool_checker).
# - The same quad opened as an .obj: framed, a default light named on stderr,
#   `photosplat-info --scene` printing a scene that loads again.
# - Every OBJ of Debian's assimp-testmodels loads or is refused with a located
#   one-line message (exit 2), never a crash, hang or leak (the asan variant's
#   programs run it too); the textured spider renders in both programs.
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
tools=${bin%/bin}/tests
[ "$bin" = bin ] && tools=build/release/tests
. tests/cli_lib.sh
ref=$bin/photosplat-ref
snap=$bin/photosplat-snap
info=$bin/photosplat-info
checker=$tools/tool_checker

d=$cli_tmp/checker
mkdir -p "$d"
if ! "$checker" write "$d"; then
    bad "tool_checker write"
else
    ok
    expect_success "ref renders the checker" "$ref" "$d/scene.scn" --hdr "$d/ref.pfm" --spp 4
    expect_success "ref: 1 % of albedo E / pi, ratio 4" "$checker" check "$d/ref.pfm" 0.01
    echo "ref:           $cli_out"
    expect_success "snap renders the checker" "$snap" "$d/scene.scn" --hdr "$d/snap.pfm"
    expect_success "snap: 2 % of albedo E / pi, ratio 4" "$checker" check "$d/snap.pfm" 0.02
    echo "snap:          $cli_out"
    expect_success "snap, float layers" "$snap" "$d/scene.scn" --hdr "$d/layers.pfm" --time 0.5 --color-depth float
    expect_success "snap layers: 2 %, ratio 4" "$checker" check "$d/layers.pfm" 0.02
    echo "snap (layers): $cli_out"
    # A missing texture: a warning naming it, the plain albedo.
    sed 's/checker.png/gone.png/' "$d/quad.mtl" >"$d/quad2.mtl"
    sed 's/quad.mtl/quad2.mtl/' "$d/quad.obj" >"$d/quad2.obj"
    expect_success "missing texture loads" "$info" "$d/quad2.obj"
    expect_match "missing texture named" "$(cat "$cli_tmp/err")" 'gone\.png.*not used'
    # The quad opened directly.
    expect_success "an .obj as the scene" "$ref" "$d/quad.obj" -o "$d/model.png" --spp 1 --quality draft
    expect_match "default light named" "$(cat "$cli_tmp/err")" 'default light 0: point at'
    (cd "$d" && "../../$info" quad.obj --scene >generated.scn 2>/dev/null) 2>/dev/null ||
        (cd "$d" && "$OLDPWD/$info" quad.obj --scene >generated.scn 2>/dev/null)
    expect_success "--scene loads back" "$info" "$d/generated.scn"
    expect_match "--scene keeps the mesh" "$(cat "$d/generated.scn")" '^mesh quad.obj'
    expect_match "--scene has the light" "$(cat "$d/generated.scn")" '^light point position'
fi

models=/usr/share/assimp/models
if [ ! -d "$models/OBJ" ]; then
    echo "cli_models: $models not installed (scripts/install-deps.sh); the model set is skipped"
else
    n=0
    for f in "$models"/OBJ/*.obj "$models"/invalid/*.obj; do
        [ -e "$f" ] || continue
        n=$((n + 1))
        timeout 120 "$info" "$f" >"$cli_tmp/out" 2>"$cli_tmp/err"
        rc=$?
        if [ $rc -eq 0 ]; then
            ok
        elif [ $rc -eq 2 ] && [ "$(grep -vc '^warning: ' "$cli_tmp/err")" -eq 1 ] &&
            grep -v '^warning: ' "$cli_tmp/err" | grep -Eq '^[^ ]+\.(obj|mtl):[0-9]+: '; then
            ok
        else
            bad "$f: exit $rc: $(grep -v '^warning: ' "$cli_tmp/err" | head -2)"
        fi
    done
    echo "cli_models: $n models of assimp-testmodels"
    spider=$models/OBJ/spider.obj
    expect_success "spider: textures loaded" "$info" "$spider"
    expect_match "spider: a JPEG texture" "$cli_out" 'texture .*SpiderTex\.jpg 249x250'
    expect_success "spider: ref" "$ref" "$spider" -o "$cli_tmp/spider-ref.png" --size 96x96 --quality draft
    expect_success "spider: snap" "$snap" "$spider" -o "$cli_tmp/spider-snap.png" --size 96x96
fi
cli_summary
