#!/usr/bin/env bash
# stress.sh: what of the numerical stress suite does not fit in `make test`
# (docs/stress.md): tests/test_stress with ten times the photons, and
# tests/cli_stress.sh with larger images and 10^7 photons into an 8-bit
# buffer. Release build only; prints each step's time and ends with
# "stress: N passed, N failed".
set -u
cd "$(dirname "$0")/.."
export PS_STRESS_FACTOR=${PS_STRESS_FACTOR:-10}
export STRESS_LONG=1
log_dir=build/stress-logs
mkdir -p "$log_dir"
failed=0
passed=0
step() { # name command...
    local name=$1 start=$SECONDS
    shift
    if "$@" >"$log_dir/$name.log" 2>&1; then
        passed=$((passed + 1))
        printf 'stress %-24s ok   (%ss)\n' "$name" $((SECONDS - start))
    else
        failed=$((failed + 1))
        printf 'stress %-24s FAIL (%ss) — log: %s\n' "$name" $((SECONDS - start)) "$log_dir/$name.log"
        grep -E 'FAIL|ERROR|error' "$log_dir/$name.log" | head -20 | sed 's/^/    | /'
    fi
    grep -E '^KNOWN BUG' "$log_dir/$name.log" | sed 's/^/    | /'
}
step test_stress build/release/tests/test_stress
step cli_stress tests/cli_stress.sh build/release/bin
echo "stress: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
