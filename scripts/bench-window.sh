#!/usr/bin/env bash
# bench-window.sh: the preview window's speed under Xvfb (make bench runs it):
# frames per second while refining with 10^5 and 10^6 photons (the view
# still, orbiting every 0.05 s while tracing, and orbiting once the maps are
# full: "orbit-full", the frame rate over every stored photon; the fps figure
# is smoothed over the last few frames), and the time from a light move to the
# first refreshed frame; the camera's level of detail (frames while moving,
# and the full picture's return after the stop). Each run is made twice, the picture composited and
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
# The camera's level of detail over the full maps (10^6 + 2.5 10^5 photons,
# GL composite): orbiting a step every 0.05 s for 2.95 s (60 steps), then
# still until every photon is drawn again. The window's own figures: the
# frames drawn while moving (at most one a step: 20 fps), their mean time,
# and the time from the last moving frame to the refresh that has drawn
# every photon again (the goal: within one tau).
echo "| photons (caustic + global) | moving frames (60 steps) | fps while moving | mean moving frame ms | full picture after the stop s | tau s |"
echo "| ---: | ---: | ---: | ---: | ---: | ---: |"
{
    echo "0 wait done"
    for t in $(seq 0.05 0.05 3); do echo "$t orbit 2 0"; done
    echo "3.05 wait done"
    echo "3.05 quit"
} >"$tmp/orbit-stop.txt"
xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 --overlay off \
    --caustic-photons 1000000 --global-photons 250000 --script "$tmp/orbit-stop.txt" --stats "$tmp/orbit-stop.json" >/dev/null
f=$tmp/orbit-stop.json
mf=$(stat_of moving_frame_seconds_mean "$f")
printf '| 1000000 + 250000 | %s | %.1f | %s | %.3f | %s |\n' "$(stat_of moving_frames "$f")" \
    "$(awk -v n="$(stat_of moving_frames "$f")" 'BEGIN { printf "%.1f", n / 2.95 }')" "$(ms "$mf")" \
    "$(stat_of full_after_stop_seconds "$f")" "$(stat_of tau "$f")"
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

# The global layer as splats and as illumination maps (--global-layer maps),
# GL composite, 10^6 caustic + 2.5*10^5 global photons: refining with the
# view still, and orbiting over the full maps (every photon drawn each frame
# as splats; the maps redrawn as one mesh pass).
echo
echo "| global layer | view | fps | frames | emitted by the end |"
echo "| --- | --- | ---: | ---: | ---: |"
for layer in splats maps; do
    for view in still orbit-full; do
        if [ $view = still ]; then lines=("4.5 quit"); else mapfile -t lines < <(full_orbit_lines); fi
        printf '%s\n' "${lines[@]}" >"$tmp/g-$layer-$view.txt"
        xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 --overlay off \
            --caustic-photons 1000000 --global-photons 250000 --global-layer $layer \
            --script "$tmp/g-$layer-$view.txt" --stats "$tmp/g-$layer-$view.json" >/dev/null
        f=$tmp/g-$layer-$view.json
        printf '| %s | %s | %.1f | %s | %s |\n' $layer $view "$(stat_of fps "$f")" "$(stat_of frames "$f")" \
            "$(($(stat_of emitted_caustic "$f") + $(stat_of emitted_global "$f")))"
    done
done
echo
echo "| edits (2 light moves, 2 mirror moves of 10 cm) | first frame after an edit, mean s | max s | restart per edit (--repair off): mean s | max s |"
echo "| ---: | ---: | ---: | ---: | ---: |"
edit_lines=("1 move light 0 0.5 1.9 0" "2 move light 0 -0.5 1.9 0" "3 move object 6 0.1 0 0" "4 move object 6 -0.1 0 0" "5 quit")
printf '%s\n' "${edit_lines[@]}" >"$tmp/edits.txt"
for r in on off; do
    xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 --overlay off \
        --caustic-photons 1000000 --global-photons 250000 --script "$tmp/edits.txt" --repair $r \
        --stats "$tmp/edits-$r.json" >/dev/null
done
printf '| %s | %.3f | %.3f | %.3f | %.3f |\n' "$(stat_of edits "$tmp/edits-on.json")" \
    "$(stat_of edit_to_frame_seconds_mean "$tmp/edits-on.json")" "$(stat_of edit_to_frame_seconds_max "$tmp/edits-on.json")" \
    "$(stat_of edit_to_frame_seconds_mean "$tmp/edits-off.json")" "$(stat_of edit_to_frame_seconds_max "$tmp/edits-off.json")"

# Photons kept per kind of edit once the maps are full (the default scene's
# counts; the two-light test scene for what only a second light shows).
echo
echo "| scene | edit | caustic kept / retraced | global kept / retraced |"
echo "| --- | --- | ---: | ---: |"
kinds=("cornell-caustic|data/scenes/cornell-caustic.scn|move light 0  0.3 1.8 0"
    "cornell-caustic|data/scenes/cornell-caustic.scn|move object 6  0.1 0 0"
    "cornell-caustic|data/scenes/cornell-caustic.scn|move object 5  0 0 -0.1"
    "cornell-caustic|data/scenes/cornell-caustic.scn|move object 2  0 0 0.125"
    "cornell-caustic|data/scenes/cornell-caustic.scn|power light 0  50 50 50"
    "cornell-caustic|data/scenes/cornell-caustic.scn|power light 0  80 100 120"
    "two lights|tests/data/good/repair.scn|power light 0  40 60 80"
    "two lights|tests/data/good/repair.scn|power light 1  40 50 60"
    "two lights|tests/data/good/repair.scn|move light 1  -0.3 1.8 0.2"
    "two lights|tests/data/good/repair.scn|angle light 1  25"
    "two lights|tests/data/good/repair.scn|move object 6  0.1 0 0")
for k in "${kinds[@]}"; do
    IFS='|' read -r label sc act <<<"$k"
    printf '0 wait done\n0 %s\n0 quit\n' "$act" >"$tmp/kind.txt"
    bin/photosplat-snap "$sc" --script "$tmp/kind.txt" --size 64x64 --shadows off --tau 0.02 \
        --stats "$tmp/kind.json" >/dev/null
    printf '| %s | %s | %s / %s | %s / %s |\n' "$label" "$act" "$(stat_of repair_kept_caustic "$tmp/kind.json")" \
        "$(stat_of repair_retraced_caustic "$tmp/kind.json")" "$(stat_of repair_kept_global "$tmp/kind.json")" \
        "$(stat_of repair_retraced_global "$tmp/kind.json")"
done

# The mirror moved 10 cm once the maps are full: the first refreshed picture
# against the converged picture of the edited scene, and the picture just
# before the edit against the same, with the repair and with a restart.
echo
echo "| mirror moved 10 cm, maps full (snap, 256x256, float) | relMSE of the picture before the edit | relMSE of the first picture after | restart (--repair off): first picture after |"
echo "| --- | ---: | ---: | ---: |"
for r in on off; do
    printf '%s\n' "0 wait done" "0 screenshot $tmp/before-$r.png" "0 move object 6  0.1 0 0" \
        "0 screenshot $tmp/first-$r.png" "0 wait done" "0 screenshot $tmp/after-$r.png" >"$tmp/rel-$r.txt"
    bin/photosplat-snap "$scene" --script "$tmp/rel-$r.txt" --repair $r --color-depth float --size 256x256 \
        --exposure 0.3 >/dev/null
done
rel() { bin/photosplat-compare "$1" "$2" | sed -n 's/.*relmse=\([^ ]*\).*/\1/p'; }
printf '| default caps (200000 + 50000) | %s | %s | %s |\n' "$(rel "$tmp/before-on.png" "$tmp/after-on.png")" \
    "$(rel "$tmp/first-on.png" "$tmp/after-on.png")" "$(rel "$tmp/first-off.png" "$tmp/after-off.png")"
