#!/usr/bin/env bash
# cli_mpi.sh BIN_DIR: photosplat-ref-mpi (photosplat-ref on MPI) against the
# single process, byte for byte: PNG, PFM, EXR, the illuminance PFM, the
# photon dump and the image-dependent --stats figures, on 2 and 3 ranks
# (oversubscribed on this machine) with different --threads; and its faults:
# a bad scene reported once with exit status 2, a rank killed mid-run and
# SIGINT to mpirun leave no output file and say why.
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
ref=$bin/photosplat-ref
mpi=$bin/photosplat-ref-mpi
if [ ! -x "$mpi" ] || ! command -v mpirun >/dev/null 2>&1; then
    echo "cli_mpi: skipped: no MPI (photosplat-ref-mpi or mpirun missing; scripts/install-deps.sh installs Open MPI)"
    cli_summary
    exit
fi
# Open MPI refuses root without these (CI runs as root); ranks may outnumber
# cores; unbound, so that the ranks share the cores as the load allows.
mpirun_=(mpirun --oversubscribe --bind-to none)
[ "$(id -u)" -eq 0 ] && mpirun_+=(--allow-run-as-root)
case "$bin" in
*asan*)
    # Open MPI's own allocations outlive MPI_Finalize: no leak report for them.
    export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0"
    ;;
esac
scene=data/scenes/cornell-caustic.scn
small=(--size 64x48 --caustic-photons 20000 --global-photons 5000 --seed 7)

# The image-dependent figures of a --stats file: times, rates, threads and
# the split's own figures left out.
figures() { grep -Ev 'seconds|per_second|"threads"|"ranks"|"dist_' "$1"; }

# same NAME A B: byte-identical files.
same() {
    if [ ! -e "$3" ]; then
        bad "$1: $3 was not written"
    elif cmp -s "$2" "$3"; then
        ok
    else
        bad "$1: $3 differs from $2"
    fi
}

expect_success "single process" "$ref" "$scene" "${small[@]}" --threads 2 -o "$cli_tmp/a.png" \
    --hdr "$cli_tmp/a.pfm" --dump-photons "$cli_tmp/a.txt" --stats "$cli_tmp/a.json"
figures "$cli_tmp/a.json" >"$cli_tmp/a.fig"
for run in "2 1" "3 2"; do
    set -- $run
    n=$1 t=$2
    expect_success "$n ranks x $t threads" "${mpirun_[@]}" -np "$n" "$mpi" "$scene" "${small[@]}" --threads "$t" \
        -o "$cli_tmp/b$n.png" --hdr "$cli_tmp/b$n.pfm" --dump-photons "$cli_tmp/b$n.txt" --stats "$cli_tmp/b$n.json"
    expect_match "$n ranks: rank 0 reports once" "$(grep -c '^caustic:' "$cli_tmp/out")" '^1$'
    same "$n ranks: PNG" "$cli_tmp/a.png" "$cli_tmp/b$n.png"
    same "$n ranks: PFM" "$cli_tmp/a.pfm" "$cli_tmp/b$n.pfm"
    same "$n ranks: photon dump" "$cli_tmp/a.txt" "$cli_tmp/b$n.txt"
    figures "$cli_tmp/b$n.json" >"$cli_tmp/b$n.fig"
    same "$n ranks: stats figures" "$cli_tmp/a.fig" "$cli_tmp/b$n.fig"
    expect_match "$n ranks: stats say the ranks" "$(cat "$cli_tmp/b$n.json")" "\"ranks\": $n,"
done
# Sanity of the comparison itself: the figures hold real values.
expect_match "figures hold the cache" "$(cat "$cli_tmp/a.fig")" '"cache_records": [1-9]'

# The box filter (tiles of pixels, not filter buffers), EXR and the
# illuminance pass (a second render over the same hooks).
expect_success "single, box" "$ref" "$scene" "${small[@]}" --threads 1 --filter box -o "$cli_tmp/c.png" \
    --hdr "$cli_tmp/c.exr" --illuminance "$cli_tmp/c-lux.pfm"
expect_success "3 ranks, box" "${mpirun_[@]}" -np 3 "$mpi" "$scene" "${small[@]}" --threads 1 --filter box \
    -o "$cli_tmp/d.png" --hdr "$cli_tmp/d.exr" --illuminance "$cli_tmp/d-lux.pfm"
same "box: PNG" "$cli_tmp/c.png" "$cli_tmp/d.png"
same "box: EXR" "$cli_tmp/c.exr" "$cli_tmp/d.exr"
same "box: illuminance" "$cli_tmp/c-lux.pfm" "$cli_tmp/d-lux.pfm"

# The tracer alone.
expect_success "photons-only, 2 ranks" "${mpirun_[@]}" -np 2 "$mpi" "$scene" --photons-only "${small[@]}" \
    --threads 2 --dump-photons "$cli_tmp/e.txt"
same "photons-only dump" "$cli_tmp/a.txt" "$cli_tmp/e.txt"

# A bad scene: rank 0's one line (mpirun adds its own box), exit 2, nothing written.
bad_scene=$(ls tests/data/bad/*.scn | head -1)
"${mpirun_[@]}" -np 3 "$mpi" "$bad_scene" -o "$cli_tmp/f.png" >"$cli_tmp/out" 2>"$cli_tmp/err"
rc=$?
[ $rc -eq 2 ] && ok || bad "bad scene: exit status $rc, expected 2"
expect_match "bad scene: reported once" "$(grep -c "^$bad_scene" "$cli_tmp/err")" '^1$'
[ ! -e "$cli_tmp/f.png" ] && ok || bad "bad scene: f.png written"

# catching_int PID: whether the process catches SIGINT (its handler
# installed: bit 2 of /proc/PID/status's SigCgt).
catching_int() {
    local mask
    mask=$(awk '/^SigCgt:/ { print $2 }' "/proc/$1/status" 2>/dev/null)
    [ -n "$mask" ] && (((16#$mask >> 1) & 1))
}
# long_run NAME SIGNAL TARGET: a run long enough to stop midway; once both
# ranks catch SIGINT, SIGNAL goes to mpirun (TARGET mpirun) or to rank 1
# (TARGET rank). (Waiting only for the ranks to exist, then 2 s, a CI run of
# the sanitizer build beside the other tests, on a slower machine, had both
# ranks end saying nothing; likeliest, the signal came before their handler,
# which here, idle, is in place 0.2-0.5 s after they exist. Not reproduced.)
long_run() {
    rm -f "$cli_tmp/g.png"
    # --quality final: long enough (about 30 s) that the signal comes midway even on an idle machine.
    "${mpirun_[@]}" -np 2 "$mpi" "$scene" --size 400x300 --quality final --threads 1 -o "$cli_tmp/g.png" \
        >"$cli_tmp/out" 2>"$cli_tmp/err" &
    local m=$! i p n
    for i in $(seq 300); do
        n=0
        for p in $(pgrep -P $m -f photosplat-ref-mpi); do
            catching_int "$p" && n=$((n + 1))
        done
        [ $n -ge 2 ] && break
        sleep 0.1
    done
    sleep 2
    if [ "$3" = mpirun ]; then
        kill "-$2" $m
    else
        kill "-$2" "$(pgrep -P $m -f photosplat-ref-mpi | tail -1)"
    fi
    wait $m
    cli_rc=$?
    cli_err=$(cat "$cli_tmp/err")
    [ $cli_rc -ne 0 ] && ok || bad "$1: exit status 0"
    [ ! -e "$cli_tmp/g.png" ] && ok || bad "$1: g.png written"
    [ -z "$(ls -a "$cli_tmp" | grep 'g\.png')" ] && ok || bad "$1: a temporary file remains: $(ls -a "$cli_tmp")"
}
long_run "rank killed" KILL rank
expect_match "rank killed: says so" "$cli_err" 'process rank [0-9]+ .*exited on signal 9'
long_run "SIGINT" INT mpirun
expect_match "SIGINT: rank 0 says how far" "$cli_err" '^photosplat-ref: (rank [0-9]+: )?interrupted .*; nothing written'
expect_match "SIGINT: once" "$(grep -c 'nothing written' "$cli_tmp/err")" '^1$'

cli_summary
