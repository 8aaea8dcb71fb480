#!/usr/bin/env bash
# cli_window_wait.sh BIN_DIR: the window's photon caps, under Xvfb. A script's
# "wait done" holds the later actions until both maps have reached their caps
# and are drawn: a light moved away and back then gives the same picture as
# before the move (the caps are the same photons), the stats say the cap was
# reached and how much the maps hold (bounded by the caps), and a wait while
# tracing is paused ends instead of hanging. make soak does the same over a
# few hundred moves.
# run-tests: alone (it times what it runs, or opens windows on Xvfb)
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
win=$bin/photosplat
scene=data/scenes/cornell-caustic.scn
# GLFW's X11 path leaks inside libX11 (see cli_window.sh).
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0"
xrun() { xvfb-run -a -s "-screen 0 1024x768x24" "$@"; }
stat_of() { sed -n "s/.*\"$1\": \([^,]*\),*/\1/p" "$2"; }
awk_true() { awk "BEGIN { exit !($1) }"; }
# Caps that take several refreshes to reach, so that a screenshot at once
# would show fewer photons than one after the wait.
caustic=100000
global=25000
common=(--size 128x128 --exposure 0.3 --overlay off --caustic-photons $caustic --global-photons $global)
# A stored photon takes 26 bytes (20-byte record, material, object); the maps
# grow by doubling, so they hold at most twice what is stored.
PHOTON_BYTES=26

cat >"$cli_tmp/wait.txt" <<SCRIPT
0    screenshot $cli_tmp/first.png   # the first refresh: only the first batch
0    wait done
0    screenshot $cli_tmp/a.png
0.1  move light 0  0.6 1.5 0.3
0.1  move object 5  0.1 0 -0.1
0.3  move light 0  0 1.9 0
0.3  move object 5  -0.1 0 0.1
0.3  wait done
0.3  screenshot $cli_tmp/b.png
0.4  quit
SCRIPT
# The photon layers: the maps after the edits are a fresh trace's, so the
# picture is the same bytes.
expect_success "session with waits" xrun "$win" "$scene" "${common[@]}" --layers direct,caustic,global \
    --script "$cli_tmp/wait.txt" --stats "$cli_tmp/wait.json"
s=$cli_tmp/wait.json
diff=$("$bin/photosplat-compare" "$cli_tmp/b.png" "$cli_tmp/a.png")
echo "after the caps, moved away and back: $diff"
rmse=$(sed -n 's/^rmse=\([^ ]*\).*/\1/p' <<<"$diff")
awk_true "$rmse == 0" && ok || bad "the picture after moving back differs: $diff"
# The specular layer (with the direct one: where its cube maps' rounds show
# most): the same bytes too. Its last round of cube faces need not start at a
# cube's first face; the layer is redrawn from all of them (the window once
# showed a face's earlier content here in most runs).
cp "$cli_tmp/first.png" "$cli_tmp/first-maps.png"
cp "$cli_tmp/a.png" "$cli_tmp/a-maps.png"
expect_success "session with waits, specular layer" xrun "$win" "$scene" "${common[@]}" --layers direct,specular \
    --script "$cli_tmp/wait.txt"
diff=$("$bin/photosplat-compare" "$cli_tmp/b.png" "$cli_tmp/a.png")
echo "with the specular layer, moved away and back: $diff"
rmse=$(sed -n 's/^rmse=\([^ ]*\).*/\1/p' <<<"$diff")
awk_true "$rmse == 0" && ok || bad "with the specular layer, the picture after moving back differs: $diff"
cp "$cli_tmp/first-maps.png" "$cli_tmp/first.png" # the checks below are of the first session
cp "$cli_tmp/a-maps.png" "$cli_tmp/a.png"
early=$("$bin/photosplat-compare" "$cli_tmp/first.png" "$cli_tmp/a.png" | sed -n 's/^rmse=\([^ ]*\).*/\1/p')
echo "the first refresh against the capped picture: rmse $early"
awk_true "$early > 0.001" && ok || bad "wait done did not wait: the first refresh already equals it (rmse $early)"
[ "$(stat_of cap_reached "$s")" = 1 ] && ok || bad "stats: cap_reached is not 1"
[ "$(stat_of caustic_cap "$s")" = $caustic ] && [ "$(stat_of global_cap "$s")" = $global ] && ok ||
    bad "stats: caps $(stat_of caustic_cap "$s") and $(stat_of global_cap "$s"), expected $caustic and $global"
[ "$(stat_of emitted_caustic "$s")" = $caustic ] && [ "$(stat_of emitted_global "$s")" = $global ] && ok ||
    bad "stats: emitted $(stat_of emitted_caustic "$s") and $(stat_of emitted_global "$s"), not the caps"
[ "$(stat_of edits "$s")" = 4 ] && ok || bad "stats: $(stat_of edits "$s") edits, expected 4"
bytes=$(stat_of photon_map_bytes "$s")
stored=$(($(stat_of stored_caustic "$s") + $(stat_of stored_global "$s")))
echo "photon maps: $stored photons stored, $bytes bytes allocated"
awk_true "$bytes >= $stored * $PHOTON_BYTES && $bytes <= 2 * $stored * $PHOTON_BYTES" && ok ||
    bad "the maps hold $bytes bytes for $stored photons (expected $PHOTON_BYTES to $((2 * PHOTON_BYTES)) a photon)"

# The memory cap: tracing stops once the maps store --max-photons photons
# (checked between batches of 16384 caustic photons and a quarter as many
# global ones), before the caps; wait done ends there too.
limit=20000
printf '0 wait done\n0 screenshot %s\n0.1 quit\n' "$cli_tmp/limited.png" >"$cli_tmp/limited.txt"
expect_success "memory cap" xrun "$win" "$scene" "${common[@]}" --layers direct,caustic,global --max-photons $limit \
    --script "$cli_tmp/limited.txt" \
    --stats "$cli_tmp/limited.json"
s=$cli_tmp/limited.json
stored=$(($(stat_of stored_caustic "$s") + $(stat_of stored_global "$s")))
echo "memory cap $limit: $stored photons stored, $(stat_of emitted_caustic "$s") + $(stat_of emitted_global "$s") emitted"
[ "$(stat_of max_photons_reached "$s")" = 1 ] && [ "$(stat_of cap_reached "$s")" = 0 ] && ok ||
    bad "memory cap: max_photons_reached $(stat_of max_photons_reached "$s"), cap_reached $(stat_of cap_reached "$s")"
awk_true "$stored >= $limit && $stored < $limit + 2 * 20480 && $(stat_of emitted_caustic "$s") < $caustic" && ok ||
    bad "memory cap: $stored stored, $(stat_of emitted_caustic "$s") caustic emitted"
# Fewer photons, the same estimate: nearer the capped picture than the first
# refresh (one batch) was.
off=$("$bin/photosplat-compare" "$cli_tmp/limited.png" "$cli_tmp/a.png" | sed -n 's/^rmse=\([^ ]*\).*/\1/p')
echo "memory-capped picture against the capped one: rmse $off (the first refresh: $early)"
awk_true "$off < $early" && ok || bad "memory cap: the picture is off the capped one by rmse $off"
expect_usage_error "negative memory cap" "$win" "$scene" --max-photons -1
expect_match "says which" "$cli_err" 'max-photons'

# Paused, the caps are never reached: the wait ends at once, the script goes on.
printf '0 set pause on\n0 wait done\n0.2 quit\n' >"$cli_tmp/paused.txt"
expect_success "wait while paused" timeout 60 xvfb-run -a -s "-screen 0 1024x768x24" "$win" "$scene" "${common[@]}" \
    --script "$cli_tmp/paused.txt" --stats "$cli_tmp/paused.json"
[ "$(stat_of cap_reached "$cli_tmp/paused.json")" = 0 ] && ok || bad "paused: stats say the cap was reached"

# The direct layer hidden: its shadow maps are never made and the direct
# light's textures never laid (--bake), and the wait does not wait for them
# (it did: the window hung here).
printf '0 wait done
0.1 orbit 10 0
0.2 wait done
0.3 quit
' >"$cli_tmp/nodirect.txt"
expect_success "wait with the direct layer hidden" timeout 60 xvfb-run -a -s "-screen 0 1024x768x24" "$win" "$scene" \
    "${common[@]}" --layers caustic --script "$cli_tmp/nodirect.txt" --stats "$cli_tmp/nodirect.json"
[ "$(stat_of direct_light_bakes "$cli_tmp/nodirect.json")" = 0 ] && ok || bad "direct layer hidden: its light laid"

cli_summary
