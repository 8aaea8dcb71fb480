#!/usr/bin/env bash
# bench.sh: runs every benchmark program (build/release/bench/bench_*) in
# turn from the repository root, as `make bench` does after building them.
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
if [ "$found" -eq 0 ]; then
    echo "bench: no programs under build/release/bench (run make bench)" >&2
    exit 2
fi
exit $status
