#!/usr/bin/env bash
# cli_window_save.sh BIN_DIR: the window keeps the user's work, under a virtual
# X server (Xvfb) as tests/cli_window.sh runs it, or skipped without one:
# an edit is autosaved within a second to NAME.autosave.scn beside the scene,
# so that SIGTERM a few seconds later loses nothing (the file loads, with the
# light where the edit put it; a scripted session autosaves only with
# --autosave on, as here); a scripted session without it writes none; starting again on the scene says that its
# autosave is newer and how to open it; the autosave of a read-only scene
# directory goes to the current one.
# run-tests: alone (it times what it runs, or opens windows on Xvfb)
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
win=$bin/photosplat
info=$bin/photosplat-info
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" # libX11's own leaks (see cli_window.sh)
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "cli_window_save: no xvfb-run: skipped"
    cli_summary
    exit $?
fi
xrun() { xvfb-run -a -s "-screen 0 1024x768x24" "$@"; }
if [[ $bin == *asan* ]]; then wait_s=8; else wait_s=4; fi

d=$cli_tmp/work
mkdir -p "$d"
cp data/scenes/cornell-caustic.scn "$d/room.scn"
printf '0.3 move light 0  0.25 1.75 0.125\n' >"$d/edit.txt"
# The window edits, then is killed by SIGTERM with no quit and no save.
xrun sh -c "\"$win\" \"$d/room.scn\" --size 96x96 --caustic-photons 20000 --global-photons 5000 \
    --autosave on --script \"$d/edit.txt\" >\"$d/out\" 2>\"$d/err\" & pid=\$!; sleep $wait_s; kill -TERM \$pid; wait \$pid; echo rc=\$? >\"$d/rc\""
rc=$(sed -n 's/rc=//p' "$d/rc" 2>/dev/null)
[ -n "$rc" ] && [ "$rc" -ne 0 ] && ok || bad "SIGTERM: exit status '$rc', expected the interrupted one"
if [ -s "$d/room.autosave.scn" ]; then
    ok
    expect_match "the edit is in the autosave" "$(cat "$d/room.autosave.scn")" \
        '^light point position 0.25 1.75 0.125 +power'
    expect_success "the autosave loads" "$info" "$d/room.autosave.scn"
    [ "$(cat "$d/room.scn")" = "$(cat data/scenes/cornell-caustic.scn)" ] && ok || bad "the scene itself was changed"
    # Opening the scene again: its autosave is newer.
    printf '0.2 quit\n' >"$d/quit.txt"
    xrun "$win" "$d/room.scn" --size 64x64 --caustic-photons 2000 --global-photons 500 --script "$d/quit.txt" \
        >"$d/out2" 2>"$d/err2"
    expect_match "says the autosave is newer" "$(cat "$d/err2")" \
        'room.autosave.scn is newer than .*room.scn.*open it with: photosplat .*room.autosave.scn'
else
    bad "no autosave after the edit and SIGTERM: $(head -3 "$d/err")"
fi

# A script alone writes no autosave (tests and demos on the bundled scenes).
cp data/scenes/cornell-caustic.scn "$d/demo.scn"
printf '0.3 move light 0  0.25 1.75 0.125\n0.8 quit\n' >"$d/demo.txt"
expect_success "scripted session" xrun "$win" "$d/demo.scn" --size 64x64 --caustic-photons 2000 \
    --global-photons 500 --script "$d/demo.txt"
[ ! -e "$d/demo.autosave.scn" ] && ok || bad "a scripted session wrote an autosave without --autosave on"

# A read-only scene directory: the autosave goes to the current directory
# (root writes anywhere: then there is nothing to show).
if [ "$(id -u)" -ne 0 ]; then
    ro=$cli_tmp/ro
    mkdir -p "$ro" "$cli_tmp/here"
    cp data/scenes/cornell-caustic.scn "$ro/lab.scn"
    chmod a-w "$ro"
    abs_win=$(cd "$(dirname "$win")" && pwd)/photosplat
    (cd "$cli_tmp/here" && xrun sh -c "\"$abs_win\" \"$ro/lab.scn\" --size 64x64 --caustic-photons 2000 \
        --global-photons 500 --autosave on --script \"$d/edit.txt\" >/dev/null 2>&1 & pid=\$!; sleep $wait_s; kill -TERM \$pid; wait \$pid")
    [ -s "$cli_tmp/here/lab.autosave.scn" ] && ok || bad "no autosave in the current directory for a read-only scene"
    chmod u+w "$ro"
fi
cli_summary
