#!/usr/bin/env bash
# bench-window.sh: the preview window's speed under Xvfb (make bench runs it):
# frames per second while refining with 10^5 and 10^6 photons (the view
# still, orbiting every 0.05 s while tracing, and orbiting once the maps are
# full: "orbit-full", the frame rate over every stored photon; the fps figure
# is smoothed over the last few frames), and the time from a light move to the
# first refreshed frame. Each run is made twice, the picture composited and
# encoded by GL (the window's default) and, as the baseline measured in the
# same run, read back and encoded on the CPU (--composite cpu): the last
# column says what the GL side saves a refresh; then the still view with the
# specular layer on and off. Prints Markdown tables; the
# figures come from the window's own --stats.
set -euo pipefail
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene=data/scenes/cornell-caustic.scn
stat_of() { sed -n "s/.*\"$1\": \([^,]*\),*/\1/p" "$2"; }

run() { # NAME PHOTONS SCRIPT-LINES...: NAME.json (GL composite) and NAME-cpu.json
    local name=$1 photons=$2 where
    shift 2
    printf '%s\n' "$@" >"$tmp/$name.txt"
    for where in gl cpu; do
        xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 --overlay off \
            --caustic-photons "$photons" --global-photons $((photons / 4)) --script "$tmp/$name.txt" \
            --composite $where --stats "$tmp/$name${where/gl/}.json" >/dev/null
    done
    mv "$tmp/${name}cpu.json" "$tmp/$name-cpu.json"
}
ms() { awk -v s="$1" 'BEGIN { printf "%.1f", 1000 * s }'; }

orbit_lines() { # an orbit step every 0.05 s for 4 s, then quit
    local t
    for t in $(seq 0.5 0.05 4.5); do echo "$t orbit 2 0"; done
    echo "4.6 quit"
}
full_orbit_lines() { # the same once both maps are full (wait done): orbiting over every photon
    local t
    echo "0 wait done"
    for t in $(seq 0.05 0.05 3); do echo "$t orbit 2 0"; done
    echo "3.1 quit"
}

echo "| photons (caustic + global) | view | fps | frames | emitted by the end | composite ms (GL) | composite ms (CPU read-back) | fps (CPU read-back) |"
echo "| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |"
for n in 100000 1000000; do
    run still-$n $n "4.5 quit"
    mapfile -t lines < <(orbit_lines)
    run orbit-$n $n "${lines[@]}"
    mapfile -t lines < <(full_orbit_lines)
    run orbit-full-$n $n "${lines[@]}"
    for view in still orbit orbit-full; do
        f=$tmp/$view-$n.json
        c=$tmp/$view-$n-cpu.json
        printf '| %d + %d | %s | %.1f | %s | %s | %s | %s | %.1f |\n' $n $((n / 4)) "$view" "$(stat_of fps "$f")" \
            "$(stat_of frames "$f")" "$(($(stat_of emitted_caustic "$f") + $(stat_of emitted_global "$f")))" \
            "$(ms "$(stat_of composite_seconds_mean "$f")")" "$(ms "$(stat_of composite_seconds_mean "$c")")" \
            "$(stat_of fps "$c")"
    done
done
echo
# The specular layer's cost (issue 15): the same still view with it on and
# off, in the same run; its cube faces are drawn within a share of tau.
echo "| layers | fps (still, 10^6 + 2.5 10^5) | frames | first frame s |"
echo "| --- | ---: | ---: | ---: |"
for layers in direct,caustic,global direct,caustic,global,specular; do
    printf '4.5 quit\n' >"$tmp/spec.txt"
    xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 --overlay off \
        --caustic-photons 1000000 --global-photons 250000 --script "$tmp/spec.txt" --layers "$layers" \
        --stats "$tmp/spec-$layers.json" >/dev/null
    f=$tmp/spec-$layers.json
    printf '| %s | %.1f | %s | %.3f |\n' "$layers" "$(stat_of fps "$f")" "$(stat_of frames "$f")" \
        "$(stat_of first_frame_seconds "$f")"
done
echo
echo "| light moves | first frame after a move, mean s | max s | mean s (CPU read-back) | tau s |"
echo "| ---: | ---: | ---: | ---: | ---: |"
run moves 1000000 "1 move light 0 0.5 1.9 0" "2 move light 0 -0.5 1.9 0" "3 move light 0 0 1.9 0.5" \
    "4 move light 0 0 1.9 0" "5 quit"
printf '| %s | %.3f | %.3f | %.3f | 0.1 |\n' "$(stat_of edits "$tmp/moves.json")" \
    "$(stat_of edit_to_frame_seconds_mean "$tmp/moves.json")" "$(stat_of edit_to_frame_seconds_max "$tmp/moves.json")" \
    "$(stat_of edit_to_frame_seconds_mean "$tmp/moves-cpu.json")"
