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
#
# Usage: scripts/bench-window.sh [SECTION...]: only those tables (all by
# default): fps, specular, orbit, moves, global, edits, latency, kinds, relmse.
# An unknown one is refused, exit status 2.
set -euo pipefail
cd "$(dirname "$0")/.."
sections=(fps specular orbit moves global edits latency kinds relmse)
for want in "$@"; do
    case " ${sections[*]} " in
    *" $want "*) ;;
    *) echo "bench-window.sh: unknown section '$want' (sections: ${sections[*]})" >&2; exit 2 ;;
    esac
done
want() { # SECTION: whether to run it
    [ ${#only[@]} -eq 0 ] && return 0
    local w
    for w in "${only[@]}"; do [ "$w" = "$1" ] && return 0; done
    return 1
}
only=("$@")
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

if want fps; then
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
fi

if want specular; then
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
fi

if want orbit; then
echo
# The camera's level of detail over the full maps (10^6 + 2.5 10^5 photons,
# GL composite): orbiting a step every 0.05 s for 2.95 s (60 steps), then
# still until every photon is drawn again. The window's own figures: the
# frames drawn while moving (at most one a step: 20 fps), their mean time,
# and the time from the last moving frame, and from the last camera step, to
# the refresh that has drawn every photon again (the goal: within one tau of
# the step); with the maps baked into
# textures on their quads (--bake on, the window's default: the wait before
# the orbit lays them) and, the baseline in the same run, without.
echo "| photons (caustic + global) | bake | moving frames (60 steps) | fps while moving | mean moving frame ms | full picture after the last moving frame s | after the last step s | tau s |"
echo "| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |"
{
    echo "0 wait done"
    for t in $(seq 0.05 0.05 3); do echo "$t orbit 2 0"; done
    echo "3.05 wait done"
    echo "3.05 quit"
} >"$tmp/orbit-stop.txt"
for bake in on off; do
    xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$scene" --size 512x512 --exposure 0.3 --overlay off \
        --caustic-photons 1000000 --global-photons 250000 --bake $bake --script "$tmp/orbit-stop.txt" \
        --stats "$tmp/orbit-stop.json" >/dev/null
    f=$tmp/orbit-stop.json
    mf=$(stat_of moving_frame_seconds_mean "$f")
    printf '| 1000000 + 250000 | %s | %s | %.1f | %s | %.3f | %.3f | %s |\n' "$bake" "$(stat_of moving_frames "$f")" \
        "$(awk -v n="$(stat_of moving_frames "$f")" 'BEGIN { printf "%.1f", n / 2.95 }')" "$(ms "$mf")" \
        "$(stat_of full_after_stop_seconds "$f")" "$(stat_of full_after_step_seconds "$f")" "$(stat_of tau "$f")"
done
fi

if want moves; then
echo
echo "| light moves | first frame after a move, mean s | max s | mean s (CPU read-back) | tau s |"
echo "| ---: | ---: | ---: | ---: | ---: |"
run moves 1000000 "1 move light 0 0.5 1.9 0" "2 move light 0 -0.5 1.9 0" "3 move light 0 0 1.9 0.5" \
    "4 move light 0 0 1.9 0" "5 quit"
printf '| %s | %.3f | %.3f | %.3f | 0.1 |\n' "$(stat_of edits "$tmp/moves.json")" \
    "$(stat_of edit_to_frame_seconds_mean "$tmp/moves.json")" "$(stat_of edit_to_frame_seconds_max "$tmp/moves.json")" \
    "$(stat_of edit_to_frame_seconds_mean "$tmp/moves-cpu.json")"
fi


if want global; then
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
fi

if want edits; then
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
fi


if want kinds; then
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
fi



# Where an edit's first refreshed frame spends its time (issue 18), per kind
# of edit, in the default scene and the area-light one: the window (512^2,
# 10^6 + 2.5*10^5 photons, 4 edits at 1 s apart, each undoing the last) and
# photosplat-snap --script on the same scripts (its own clock, no display).
# The clock starts before the edit's call (which holds the tracing thread
# between batches) and stops when the refresh is shown (app/latency.h): the
# first, which at these caps is the level of detail, and the first at full
# detail ("full view");
# "shadows" is the shadow-cube faces rendered again (faces a frame, only
# those an edit can change) and "draw" the rest of the layers' drawing
# (depth prepass, direct light through the shadow cubes, splats).
if want latency; then
echo
echo "| program | scene | edit | first frame after an edit, mean s | max s | full view, mean s | max s | hold | update | session | specular | shadows (faces) | draw | show | other |"
echo "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
lat_kinds=("cornell-caustic|data/scenes/cornell-caustic.scn|move object|move object 6  0.1 0 0|move object 6  -0.1 0 0"
    "cornell-caustic|data/scenes/cornell-caustic.scn|move light|move light 0  0.3 1.9 0|move light 0  0 1.9 0"
    "cornell-caustic|data/scenes/cornell-caustic.scn|power|power light 0  50 50 50|power light 0  100 100 100"
    "cornell-caustic-area|data/scenes/cornell-caustic-area.scn|move object|move object 6  0.1 0 0|move object 6  -0.1 0 0"
    "cornell-caustic-area|data/scenes/cornell-caustic-area.scn|move light|move light 0  0.05 1.999 -0.25|move light 0  -0.25 1.999 -0.25"
    "cornell-caustic-area|data/scenes/cornell-caustic-area.scn|power|power light 0  50 50 50|power light 0  100 100 100")
ph() { awk -v s="$(stat_of "edit_$1_seconds_mean" "$2")" 'BEGIN { printf "%.3f", s }'; }
for k in "${lat_kinds[@]}"; do
    IFS='|' read -r label sc kind there back <<<"$k"
    printf '%s\n' "1 $there" "2 $back" "3 $there" "4 $back" "5 quit" >"$tmp/lat.txt"
    xvfb-run -a -s "-screen 0 1024x768x24" bin/photosplat "$sc" --size 512x512 --exposure 0.3 --overlay off \
        --caustic-photons 1000000 --global-photons 250000 --script "$tmp/lat.txt" --stats "$tmp/lat-w.json" >/dev/null
    bin/photosplat-snap "$sc" --size 512x512 --exposure 0.3 --color-depth float --caustic-photons 1000000 \
        --global-photons 250000 --script "$tmp/lat.txt" --stats "$tmp/lat-s.json" >/dev/null
    for prog in w s; do
        f=$tmp/lat-$prog.json
        printf '| %s | %s | %s | %.3f | %.3f | %.3f | %.3f | %s | %s | %s | %s | %s (%s) | %s | %s | %s |\n' \
            "$([ $prog = w ] && echo window || echo snap --script)" "$label" "$kind" \
            "$(stat_of edit_to_frame_seconds_mean "$f")" "$(stat_of edit_to_frame_seconds_max "$f")" \
            "$(stat_of edit_to_full_frame_seconds_mean "$f")" "$(stat_of edit_to_full_frame_seconds_max "$f")" \
            "$(ph hold "$f")" "$(ph update "$f")" "$(ph session "$f")" "$(ph specular "$f")" "$(ph shadows "$f")" \
            "$(stat_of edit_shadow_faces_mean "$f")" "$(ph draw "$f")" "$(ph show "$f")" "$(ph other "$f")"
    done
done
fi

# The mirror moved 10 cm once the maps are full (issue 18's second goal),
# photosplat-snap --script, 256^2, float layers, default caps: the first
# refreshed picture's relMSE against the converged picture of the EDITED
# scene, over the relMSE of the picture just before the edit against the
# converged picture of the UNEDITED scene (goal: at most 2). "Converged":
# the same preview with 8x the caps (1.6*10^6 + 4*10^5), maps full. The
# pictures are the screenshots' linear radiance (.pfm), as shown; the
# restart (--repair off) is the baseline, in the same run.
if want relmse; then
echo
echo "| mirror moved 10 cm, maps full (snap --script, 256x256, float) | relMSE before the edit (vs unedited converged) | first picture after (vs edited converged) | ratio (goal <= 2) | restart: first picture after | restart: ratio | 1 s after (repair) |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"
common=(--color-depth float --size 256x256 --exposure 0.3)
printf '%s\n' "0 wait done" "0 screenshot $tmp/conv-unedited.pfm" >"$tmp/cu.txt"
printf '%s\n' "0 move object 6  0.1 0 0" "0 wait done" "0 screenshot $tmp/conv-edited.pfm" >"$tmp/ce.txt"
for c in cu ce; do
    bin/photosplat-snap "$scene" --script "$tmp/$c.txt" "${common[@]}" --caustic-photons 1600000 \
        --global-photons 400000 >/dev/null
done
for r in on off; do
    # Script times count from the first frame: the edit at 10 s (the maps
    # are full by then: wait done takes 2-4 s), the later picture 1 s after.
    printf '%s\n' "0 wait done" "10 screenshot $tmp/before-$r.pfm" "10 move object 6  0.1 0 0" \
        "10 screenshot $tmp/first-$r.pfm" "11 screenshot $tmp/later-$r.pfm" "11 quit" >"$tmp/rel-$r.txt"
    bin/photosplat-snap "$scene" --script "$tmp/rel-$r.txt" --repair $r "${common[@]}" >/dev/null
done
rel() { bin/photosplat-compare "$1" "$2" | sed -n 's/.*relmse=\([^ ]*\).*/\1/p'; }
b_on=$(rel "$tmp/before-on.pfm" "$tmp/conv-unedited.pfm")
f_on=$(rel "$tmp/first-on.pfm" "$tmp/conv-edited.pfm")
b_off=$(rel "$tmp/before-off.pfm" "$tmp/conv-unedited.pfm")
f_off=$(rel "$tmp/first-off.pfm" "$tmp/conv-edited.pfm")
l_on=$(rel "$tmp/later-on.pfm" "$tmp/conv-edited.pfm")
awk -v b="$b_on" -v f="$f_on" -v bo="$b_off" -v fo="$f_off" -v l="$l_on" \
    'BEGIN { printf "| default caps (200000 + 50000) | %.4g | %.4g | %.2f | %.4g | %.2f | %.4g |\n", b, f, f / b, fo, fo / bo, l }'
fi
