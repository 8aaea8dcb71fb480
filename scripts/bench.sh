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
for b in build/release/bench/bench_*; do
    [ -x "$b" ] || continue
    case "$b" in *.d) continue ;; esac
    found=1
    echo "== $(basename "$b")"
    start=$SECONDS
    if ! "$b"; then
        echo "== $(basename "$b"): FAILED" >&2
        status=1
    fi
    echo "== $(basename "$b"): $((SECONDS - start)) s"
    echo
done
# photosplat-ref against POV-Ray on the default scene. It takes about ten
# minutes until its references are cached (bench/results/cache), a few after;
# PS_BENCH_REF=0 skips it.
if [ "${PS_BENCH_REF:-1}" != 0 ]; then
    echo "== bench-ref"
    start=$SECONDS
    if ! scripts/bench-ref.sh; then
        echo "== bench-ref: FAILED" >&2
        status=1
    fi
    echo "== bench-ref: $((SECONDS - start)) s"
    echo
fi
# The preview's error against time on the four bench scenes (photosplat-bench):
# bench/results/bench.{csv,md,png}. About 25 minutes on 2 cores with its
# references cached, 10 more without; PS_BENCH_QUICK=1 runs its --quick
# subset, PS_BENCH_PREVIEW=0 skips it.
if [ "${PS_BENCH_PREVIEW:-1}" != 0 ]; then
    echo "== photosplat-bench"
    start=$SECONDS
    quick=()
    [ "${PS_BENCH_QUICK:-0}" != 0 ] && quick=(--quick)
    if ! bin/photosplat-bench "${quick[@]}"; then
        echo "== photosplat-bench: FAILED" >&2
        status=1
    fi
    echo "== photosplat-bench: $((SECONDS - start)) s"
    echo
fi
# The window's frames per second and edit latency, under Xvfb.
echo "== bench-window"
start=$SECONDS
if ! scripts/bench-window.sh; then
    echo "== bench-window: FAILED" >&2
    status=1
fi
echo "== bench-window: $((SECONDS - start)) s"
echo
if [ "$found" -eq 0 ]; then
    echo "bench: no programs under build/release/bench (run make bench)" >&2
    exit 2
fi
exit $status
