#!/usr/bin/env bash
# valgrind.sh: the GL-free programs and unit tests (release build) under
# valgrind's memcheck: --error-exitcode=1 --leak-check=full, small inputs.
# Each run must end with the exit status it expects (2 for the refusals,
# 130 for the interrupted render) and valgrind must report nothing. Prints
# one line per run and a summary "valgrind: N passed, N failed"; exit 0 only
# when all passed. VALGRIND_JOBS runs (default 2) go side by side.
#
# Left out: OSMesa and GLFW programs and tests (the GL drivers' own reports
# are not ours), and test_render, test_tracer, test_accel and test_photon (two
# to five minutes each under valgrind; the same renderer, tracer and
# accelerator run in the photosplat-ref cases below, and the whole tests
# under ASan in `make test`).
set -u
cd "$(dirname "$0")/.."
rel=build/release
jobs=${VALGRIND_JOBS:-2}
skip=" test_render test_tracer test_accel test_photon "
log_dir=build/valgrind-logs
rm -rf "$log_dir"
mkdir -p "$log_dir"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/photosplat-valgrind.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
scene=data/scenes/cornell-caustic.scn
area=data/scenes/cornell-caustic-area.scn
small="--caustic-photons 4000 --global-photons 2000"
vg="valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,indirect,possible"

# Each case: NAME EXPECTED_STATUS COMMAND (a shell line, run under valgrind).
cases=()
for t in $rel/tests/test_*; do
    n=$(basename "$t")
    case "$n" in *.d | test_gl*) continue ;; esac
    case "$skip" in *" $n "*) continue ;; esac
    cases+=("$n|0|$t")
done
cases+=(
    "info|0|$rel/bin/photosplat-info $scene"
    "info-area|0|$rel/bin/photosplat-info $area"
    "ref-image|0|$rel/bin/photosplat-ref $scene -o $tmp/a.png --hdr $tmp/a.pfm --stats $tmp/a.json --size 24x24 --spp 1 --gather 4 --cache-rays 16 $small"
    "ref-area-photons|0|$rel/bin/photosplat-ref $area --photons-only --dump-photons $tmp/d.txt --threads 2 $small"
    "ref-direct-nocache|0|$rel/bin/photosplat-ref $area -o $tmp/b.png --size 16x16 --spp 1 --cache 0 --gather 2 $small"
    "compare|0|$rel/bin/photosplat-compare tests/data/golden/$(ls tests/data/golden | grep -m1 '\.png$') tests/data/golden/$(ls tests/data/golden | grep -m1 '\.png$')"
    "ref-bad-scene|2|$rel/bin/photosplat-ref tests/data/bad/01-unknown-statement.scn --photons-only"
    "ref-over-budget|2|env PS_MEMORY_LIMIT=1M $rel/bin/photosplat-ref $scene -o $tmp/c.png"
    "ref-map-cap|2|env PS_MEMORY_LIMIT=4M $rel/bin/photosplat-ref $scene --photons-only --caustic-photons 0 --global-photons 50000"
    "ref-unwritable|2|$rel/bin/photosplat-ref $scene -o $tmp/none/c.png"
    "ref-dev-full|2|$rel/bin/photosplat-ref $scene --hdr /dev/full --size 8x8 --spp 1 $small"
    "compare-not-a-file|2|$rel/bin/photosplat-compare /dev/zero $tmp"
    # SIGINT after 20 s: the render stops between tiles and frees everything.
    "ref-interrupted|130|$rel/bin/photosplat-ref $scene -o $tmp/i.png --size 128x128 --spp 256 $small"
)

run_case() { # NAME|STATUS|COMMAND
    local name=${1%%|*} rest=${1#*|}
    local want=${rest%%|*} cmd=${rest#*|}
    local log=$log_dir/$name.log start=$SECONDS
    local rc
    # shellcheck disable=SC2086
    if [ "$want" -eq 130 ]; then
        timeout --preserve-status -s INT 20 $vg $cmd >"$log" 2>&1
    else
        timeout 600 $vg $cmd >"$log" 2>&1
    fi
    rc=$?
    if [ "$rc" -eq "$want" ] && ! grep -q '^==[0-9]*== ' "$log"; then
        printf 'ok   %-22s (%ss)\n' "$name" $((SECONDS - start))
    else
        printf 'FAIL %-22s exit %s, expected %s (%ss) — log: %s\n' "$name" "$rc" "$want" $((SECONDS - start)) "$log"
        grep '^==[0-9]*== ' "$log" | head -20 | sed 's/^/    | /'
    fi
}
export -f run_case
export vg log_dir
start=$SECONDS
printf '%s\n' "${cases[@]}" | xargs -d '\n' -P "$jobs" -I{} bash -c 'run_case "$1"' _ {} | tee "$tmp/results"
passed=$(grep -c '^ok' "$tmp/results")
failed=$(grep -c '^FAIL' "$tmp/results")
echo "valgrind: $passed passed, $failed failed ($((SECONDS - start)) s)"
[ "$failed" -eq 0 ]
