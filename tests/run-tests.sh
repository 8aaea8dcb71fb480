#!/usr/bin/env bash
# run-tests.sh: runs every unit test (cmocka) and the command-line tests, from
# the release build and under AddressSanitizer + UBSan, and ends with one
# summary line "tests: N passed, N failed". PS_TEST_JOBS: how many run at
# once in the first phase (default 2).
set -u
cd "$(dirname "$0")/.."

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# libOSMesa's own 480-byte leak is the only one we accept (platform notes).
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"

passed=0
failed=0
failed_names=()
ran=0 # tests counted, against those listed (a runner that skipped some must fail)
log_dir=build/test-logs
mkdir -p "$log_dir"

# failure_lines LOG N: the first N lines of a failed test's log that say why.
failure_lines() {
    sed -e 's/^/    | /' "$1" | grep -E 'FAIL|ERROR|error|Sanitizer|runtime error|^    \| [^[]' | head -"$2"
}

# count LOG RC VARIANT NAME SECONDS: adds a finished test's counts to the
# totals and prints its line. cmocka prints "[  PASSED  ] N test(s)." and
# "[  FAILED  ] N test(s)"; the CLI scripts print "cli: N passed, N failed".
count() {
    local log=$1 rc=$2 variant=$3 name=$4 took=$5
    local p f
    p=$(grep -Eo '\[  PASSED  \] [0-9]+ test' "$log" | grep -Eo '[0-9]+' | tail -1)
    f=$(grep -Eo '\[  FAILED  \] [0-9]+ test' "$log" | grep -Eo '[0-9]+' | tail -1)
    if [ -z "$p" ]; then
        p=$(grep -Eo '^cli: [0-9]+ passed' "$log" | grep -Eo '[0-9]+' | tail -1)
        f=$(grep -Eo '^cli: [0-9]+ passed, [0-9]+ failed' "$log" | grep -Eo '[0-9]+ failed' | grep -Eo '[0-9]+')
    fi
    p=${p:-0}
    f=${f:-0}
    ran=$((ran + 1))
    # A crash or sanitizer report ends the binary early: count it as a failure
    # even when no test said so.
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    passed=$((passed + p))
    failed=$((failed + f))
    if [ "$rc" -ne 0 ]; then
        failed_names+=("$variant/$name")
        printf '%-8s %-28s FAIL (%ss) — log: %s\n' "$variant" "$name" "$took" "$log"
        failure_lines "$log" 40
    else
        printf '%-8s %-28s ok   %3d passed (%ss)\n' "$variant" "$name" "$p" "$took"
    fi
}

# The tests, as "variant name command..." lines (one word each). Unit tests
# first: the sanitizer build's, the longer, lead.
jobs_of() { # PHASE: shared or alone
    local want=$1 variant t c
    if [ "$want" = shared ]; then
        for variant in asan release; do
            for t in build/$variant/tests/test_*; do
                [ -x "$t" ] || continue
                case "$t" in *.d) continue ;; esac
                echo "$variant $(basename "$t") $t"
            done
        done
    fi
    for variant in release asan; do
        for c in tests/cli_*.sh; do
            [ "$c" = tests/cli_lib.sh ] && continue
            # A script that times what it runs (a checkpoint's lateness, an
            # edit's latency, a window's frames) says "run-tests: alone": it
            # runs with nothing beside it.
            if grep -q '^# run-tests: alone' "$c"; then
                [ "$want" = alone ] || continue
            else
                [ "$want" = shared ] || continue
            fi
            echo "$variant $(basename "$c" .sh) $c build/$variant/bin"
        done
    done
}

# Phase 1: the unit tests and the scripts that time nothing, two at a time
# (on 2 cores the suite took 12-13 minutes one at a time; the unit tests'
# time bounds are for quadratic blow-ups, far from their times). Each line
# is printed as its test ends.
SHARED_JOBS=${PS_TEST_JOBS:-2}
if ! [[ $SHARED_JOBS =~ ^[1-9][0-9]*$ ]]; then
    echo "run-tests.sh: PS_TEST_JOBS must be a whole number of at least 1, not '$SHARED_JOBS'" >&2
    exit 2
fi
declare -A job_line=() job_start=()
reap() { # waits for one running test and counts it
    local done_pid rc v n
    wait -n -p done_pid
    rc=$?
    if [ -z "${done_pid:-}" ]; then
        # `wait -n` found nothing while one of ours was not counted yet (a
        # clean-clone run, cli_runner's PS_TEST_JOBS=1 over stand-ins: 9 of
        # 10 counted; not reproduced in 45 runs since). bash keeps a finished
        # background job's status for `wait PID` once it is off the job
        # table (POSIX asks it to): ask each of ours that is gone.
        local pid
        for pid in "${!job_line[@]}"; do
            kill -0 "$pid" 2>/dev/null && continue
            wait "$pid"
            rc=$?
            done_pid=$pid
            break
        done
        if [ -z "${done_pid:-}" ]; then # nothing left to wait for: the rest are not counted, and fail
            job_line=()
            return 0
        fi
    fi
    [ -n "${job_line[$done_pid]+x}" ] || return 0 # not one of ours
    read -r v n <<<"${job_line[$done_pid]}"
    count "$log_dir/$v-$n.log" "$rc" "$v" "$n" $((SECONDS - ${job_start[$done_pid]}))
    unset "job_line[$done_pid]" "job_start[$done_pid]"
}
# run_phase WIDTH PHASE: the phase's tests, at most WIDTH at a time.
run_phase() {
    local width=$1 variant name cmd
    while read -r variant name cmd; do
        while [ ${#job_line[@]} -ge "$width" ]; do reap; done
        # shellcheck disable=SC2086 # the command's words
        $cmd >"$log_dir/$variant-$name.log" 2>&1 </dev/null &
        job_line[$!]="$variant $name"
        job_start[$!]=$SECONDS
    done < <(jobs_of "$2")
    while [ ${#job_line[@]} -gt 0 ]; do reap; done
}
run_phase "$SHARED_JOBS" shared
# Phase 2: the scripts that time what they run, one at a time.
run_phase 1 alone

listed=$( (jobs_of shared; jobs_of alone) | wc -l)
if [ "$ran" -ne "$listed" ]; then
    failed_names+=("runner: $ran of $listed tests ran")
    failed=$((failed + 1))
fi
if [ ${#failed_names[@]} -gt 0 ]; then
    # Each failure's lines again, last: a CI report may keep only the output's
    # tail, and the lines printed as the test ended are then long scrolled off.
    for f in "${failed_names[@]}"; do
        log="$log_dir/${f/\//-}.log" # variant/name: the log variant-name.log
        [ -f "$log" ] || continue
        echo "$f:"
        failure_lines "$log" 20
    done
    echo "failed: ${failed_names[*]}"
fi
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ ${#failed_names[@]} -eq 0 ]
