#!/usr/bin/env bash
# cli_info.sh BIN_DIR: photosplat-info from the outside: options, the default
# scenes, and every malformed scene of tests/data/bad (exit 2, one line
# "file:line: problem", nothing on stdout).
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
info=$bin/photosplat-info

expect_success "--help" "$info" --help
expect_match "--help text" "$cli_out" '^usage: photosplat-info SCENE'
expect_usage_error "no arguments" "$info"
expect_usage_error "unknown option" "$info" --frobnicate data/scenes/cornell-caustic.scn
expect_match "unknown option names it" "$cli_err" "unknown option '--frobnicate'"
expect_usage_error "two scenes" "$info" data/scenes/cornell-caustic.scn data/scenes/cornell-caustic-area.scn
expect_usage_error "missing file" "$info" tests/data/no-such.scn
expect_match "missing file named" "$cli_err" '^tests/data/no-such.scn: cannot open'
expect_usage_error "directory" "$info" tests/data
expect_usage_error "device" "$info" /dev/null

# Every bundled scene loads and says what lights it has.
declare -A lights=(
    [data/scenes/cornell-caustic.scn]='^lights +1, total power 100 100 100 W'
    [data/scenes/cornell-caustic-area.scn]='^lights +1, total power 100 100 100 W'
    [data/scenes/ring-caustic.scn]='^lights +1, total power 16 16 16 W'
    [data/scenes/design-room.scn]='^lights +2, total power 110 103 94 W'
    [data/scenes/gallery.scn]='^lights +7, total power 18.393 17.6186 16.6865 W, 12100 lm'
)
for scene in data/scenes/*.scn; do
    expect_success "$scene" "$info" "$scene"
    if [ -n "${lights[$scene]:-}" ]; then
        expect_match "$scene lights" "$cli_out" "${lights[$scene]}"
    else
        bad "$scene: a bundled scene this test does not know: add its lights above"
    fi
done
expect_match "ring: the mesh loaded" "$("$info" data/scenes/ring-caustic.scn)" '1540 triangles'
expect_match "design room: the caustic pass" "$("$info" data/scenes/design-room.scn)" 'caustic: needed'

count=0
for scene in tests/data/bad/*.scn; do
    expect=$(head -1 "$scene")
    line=$(printf '%s' "$expect" | sed -E 's/^# expect: ([0-9]+): .*/\1/')
    expect_usage_error "$scene" "$info" "$scene"
    # The scene's own line, or for a broken OBJ its line and "(mesh at scene:N)".
    expect_match "$scene location" "$cli_err" "^($scene:$line: |[^ ]+:$line: .*\\(mesh at $scene:[0-9]+\\))"
    count=$((count + 1))
done
[ $count -ge 25 ] && ok || bad "only $count malformed scenes"

cli_summary
