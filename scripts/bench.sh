#!/usr/bin/env bash
# bench.sh: runs every benchmark program (build/release/bench/bench_*) in
# turn from the repository root, as `make bench` does after building them,
# then scripts/bench-ref.sh (photosplat-ref against POV-Ray), photosplat-bench
# (the preview's error against time) and scripts/bench-window.sh.
# Exits non-zero when any of them fails.
set -u
cd "$(dirname "$0")/.."

status=0
found=0
# step NAME CMD...: one more benchmark, timed; a failure is reported and
# remembered, the others still run.
step() {
    local name=$1 start=$SECONDS
    shift
    echo "== $name"
    if ! "$@"; then
        echo "== $name: FAILED" >&2
        status=1
    fi
    echo "== $name: $((SECONDS - start)) s"
    echo
}
for b in build/release/bench/bench_*; do
    [ -x "$b" ] || continue
    case "$b" in *.d) continue ;; esac
    found=1
    step "$(basename "$b")" "$b"
done
# photosplat-ref against POV-Ray on the default scene. It takes about ten
# minutes until its references are cached (bench/results/cache), a few after;
# PS_BENCH_REF=0 skips it.
[ "${PS_BENCH_REF:-1}" != 0 ] && step bench-ref scripts/bench-ref.sh
# The preview's error against time on the four bench scenes (photosplat-bench):
# bench/results/bench.{csv,md,png}. 16 minutes on 2 cores with its references
# rendered (4 of those minutes; 12 cached); PS_BENCH_QUICK=1 runs its --quick subset,
# PS_BENCH_PREVIEW=0 skips it.
quick=()
[ "${PS_BENCH_QUICK:-0}" != 0 ] && quick=(--quick)
[ "${PS_BENCH_PREVIEW:-1}" != 0 ] && step photosplat-bench bin/photosplat-bench "${quick[@]}"
# photosplat-ref-mpi: 2 ranks x 1 thread against 1 process x 2 threads, and
# the phases' model of more ranks (bench/results/mpi.txt); about 2 minutes;
# PS_BENCH_MPI=0 skips it.
[ "${PS_BENCH_MPI:-1}" != 0 ] && step bench-mpi scripts/bench-mpi.sh
# The window's frames per second and edit latency, under Xvfb.
step bench-window scripts/bench-window.sh
if [ "$found" -eq 0 ]; then
    echo "bench: no programs under build/release/bench (run make bench)" >&2
    exit 2
fi
exit $status
