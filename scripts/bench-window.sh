#!/usr/bin/env bash
# bench-window.sh: the preview window's speed under Xvfb (make bench runs it):
# frames per second while refining with 10^5 and 10^6 photons (the view
# still, and orbiting every frame), and the time from a light move to the
# first refreshed frame. Prints a Markdown table; the figures come from the
# window's own --stats.
set -euo pipefail
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene=data/scenes/cornell-caustic.scn
stat_of() { sed -n "s/.*\"$1\": \([^,]*\),*/\1/p" "$2"; }

run() { # NAME PHOTONS SCRIPT-LINES...
    local name=$1 photons=$2
    shift 2
    printf '%s\n' "$@" >"$tmp/$name.txt"
    xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 --overlay off \
        --caustic-photons "$photons" --global-photons $((photons / 4)) --script "$tmp/$name.txt" \
        --stats "$tmp/$name.json" >/dev/null
}

orbit_lines() { # an orbit step every 0.05 s for 4 s, then quit
    local t
    for t in $(seq 0.5 0.05 4.5); do echo "$t orbit 2 0"; done
    echo "4.6 quit"
}

echo "| photons (caustic + global) | view | fps | frames | emitted by the end | composite ms |"
echo "| ---: | --- | ---: | ---: | ---: | ---: |"
for n in 100000 1000000; do
    run still-$n $n "4.5 quit"
    mapfile -t lines < <(orbit_lines)
    run orbit-$n $n "${lines[@]}"
    for view in still orbit; do
        f=$tmp/$view-$n.json
        printf '| %d + %d | %s | %.1f | %s | %s | %.2f |\n' $n $((n / 4)) "$view" "$(stat_of fps "$f")" "$(stat_of frames "$f")" \
            "$(($(stat_of emitted_caustic "$f") + $(stat_of emitted_global "$f")))" \
            "$(awk -v s="$(stat_of composite_seconds_mean "$f")" 'BEGIN { print 1000 * s }')"
    done
done
echo
echo "| light moves | first frame after a move, mean s | max s | tau s |"
echo "| ---: | ---: | ---: | ---: |"
run moves 1000000 "1 move light 0 0.5 1.9 0" "2 move light 0 -0.5 1.9 0" "3 move light 0 0 1.9 0.5" \
    "4 move light 0 0 1.9 0" "5 quit"
printf '| %s | %.3f | %.3f | 0.1 |\n' "$(stat_of edits "$tmp/moves.json")" \
    "$(stat_of edit_to_frame_seconds_mean "$tmp/moves.json")" "$(stat_of edit_to_frame_seconds_max "$tmp/moves.json")"
