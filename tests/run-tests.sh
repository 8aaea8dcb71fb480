#!/usr/bin/env bash
# run-tests.sh: runs every unit test (cmocka) and the command-line tests, first
# from the release build, then under AddressSanitizer + UBSan, and ends with
# one summary line "tests: N passed, N failed".
set -u
cd "$(dirname "$0")/.."

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# libOSMesa's own 480-byte leak is the only one we accept (platform notes).
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"

passed=0
failed=0
failed_names=()
log_dir=build/test-logs
mkdir -p "$log_dir"

run_one() { # variant name command...
    local variant=$1 name=$2
    shift 2
    local log="$log_dir/$variant-$name.log"
    local start=$SECONDS
    "$@" >"$log" 2>&1
    local rc=$?
    # cmocka prints "[  PASSED  ] N test(s)." and "[  FAILED  ] N test(s)"; the
    # CLI script prints "cli: N passed, N failed".
    local p f
    p=$(grep -Eo '\[  PASSED  \] [0-9]+ test' "$log" | grep -Eo '[0-9]+' | tail -1)
    f=$(grep -Eo '\[  FAILED  \] [0-9]+ test' "$log" | grep -Eo '[0-9]+' | tail -1)
    if [ -z "$p" ]; then
        p=$(grep -Eo '^cli: [0-9]+ passed' "$log" | grep -Eo '[0-9]+' | tail -1)
        f=$(grep -Eo '^cli: [0-9]+ passed, [0-9]+ failed' "$log" | grep -Eo '[0-9]+ failed' | grep -Eo '[0-9]+')
    fi
    p=${p:-0}
    f=${f:-0}
    # A crash or sanitizer report ends the binary early: count it as a failure
    # even when no test said so.
    if [ $rc -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    passed=$((passed + p))
    failed=$((failed + f))
    if [ $rc -ne 0 ]; then
        failed_names+=("$variant/$name")
        printf '%-8s %-28s FAIL (%ss) — log: %s\n' "$variant" "$name" $((SECONDS - start)) "$log"
        sed -e 's/^/    | /' "$log" | grep -E 'FAIL|ERROR|error|Sanitizer|runtime error|^    \| [^[]' | head -40
    else
        printf '%-8s %-28s ok   %3d passed (%ss)\n' "$variant" "$name" "$p" $((SECONDS - start))
    fi
}

for variant in release asan; do
    for t in build/$variant/tests/test_*; do
        [ -x "$t" ] || continue
        case "$t" in *.d) continue ;; esac
        run_one "$variant" "$(basename "$t")" "$t"
    done
    for c in tests/cli_*.sh; do
        [ "$c" = tests/cli_lib.sh ] && continue
        run_one "$variant" "$(basename "$c" .sh)" "$c" "build/$variant/bin"
    done
done

if [ ${#failed_names[@]} -gt 0 ]; then
    echo "failed: ${failed_names[*]}"
fi
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ ${#failed_names[@]} -eq 0 ]
