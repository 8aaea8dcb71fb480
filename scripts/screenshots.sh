#!/usr/bin/env bash
# screenshots.sh: real screenshots of the preview window (bin/photosplat) for
# the README, taken under a virtual X server by --script sessions, into
# screenshots/. `make screenshots` runs it.
set -euo pipefail
cd "$(dirname "$0")/.."
out=screenshots
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene=data/scenes/cornell-caustic.scn
# 2 million caustic photons: the window refines for several seconds.
window() {
    xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 \
        --caustic-photons 2000000 --global-photons 400000 "$@" >/dev/null
}
session() { # NAME LINES...: a script from the remaining arguments, one line each
    local name=$1
    shift
    printf '%s\n' "$@" >"$tmp/$name.txt"
    echo "$tmp/$name.txt"
}

window --script "$(session refine "0.2 screenshot $out/refining-0.2s.png" "4 screenshot $out/refined-4s.png" \
    "4.1 quit")"
window --script "$(session move "2 move light 0  0.6 1.9 0" "2.3 screenshot $out/light-moved-0.3s.png" \
    "6 screenshot $out/light-moved-4s.png" "6.1 quit")"
window --splat points --script "$(session points "4 screenshot $out/points-4s.png" "4.1 quit")"
window --overlay off --script "$(session triangles "4 screenshot $out/triangles-4s.png" "4.1 quit")"
ls -1 "$out"/*.png
