#!/usr/bin/env bash
# cli_runner.sh [BIN_DIR]: tests/run-tests.sh itself (no program is run), over a tree of stand-in
# tests (shell scripts that print what cmocka and the CLI scripts print): the
# totals, a failing test named, a bad PS_TEST_JOBS refused, and a runner that
# counts fewer tests than it listed failing (the first two-phase version ran
# no unit tests under set -u and said "0 failed").
set -u
cd "$(dirname "$0")/.."
. tests/cli_lib.sh
tree=$cli_tmp/tree
mkdir -p "$tree/tests"
for v in release asan; do
    mkdir -p "$tree/build/$v/tests" "$tree/build/$v/bin"
    for t in a b c; do
        printf '#!/bin/sh\necho "[  PASSED  ] 2 test(s)."\n' >"$tree/build/$v/tests/test_$t"
    done
done
printf '#!/bin/sh\necho "cli: 3 passed, 0 failed"\n' >"$tree/tests/cli_x.sh"
printf '#!/bin/sh\n# run-tests: alone\necho "cli: 1 passed, 0 failed"\n' >"$tree/tests/cli_y.sh"
: >"$tree/tests/cli_lib.sh"
chmod +x "$tree"/build/*/tests/test_* "$tree"/tests/cli_*.sh
cp tests/run-tests.sh "$tree/tests/"

# 6 unit tests of 2 and 4 scripts (two untimed of 3, two alone of 1).
expect_success "runner" "$tree/tests/run-tests.sh"
expect_match "runner totals" "$(tail -1 <<<"$cli_out")" '^tests: 20 passed, 0 failed$'
expect_match "alone last" "$(grep -E '^(release|asan) ' <<<"$cli_out" | tail -2 | awk '{print $2}' | tr '\n' ' ')" \
    '^cli_y cli_y $'
PS_TEST_JOBS=1 "$tree/tests/run-tests.sh" >"$cli_tmp/one" 2>&1 && ok || bad "PS_TEST_JOBS=1: $(tail -3 "$cli_tmp/one")"
# A failing test: named, counted, and the runner fails.
printf '#!/bin/sh\necho "[  ERROR   ] --- the reason"\necho "[  FAILED  ] 1 test(s), listed below:"\nexit 1\n' >"$tree/build/release/tests/test_b"
"$tree/tests/run-tests.sh" >"$cli_tmp/f" 2>&1
rc=$?
[ $rc -ne 0 ] && ok || bad "a failing test: the runner exited 0"
expect_match "failing test named" "$(cat "$cli_tmp/f")" 'failed: release/test_b'
expect_match "failing totals" "$(tail -1 "$cli_tmp/f")" '^tests: 18 passed, 1 failed$'
# Its reason again in the last lines (a CI report may keep only the tail).
expect_match "failure's reason last" "$(tail -5 "$cli_tmp/f" | tr '\n' ' ')" 'release/test_b: .*the reason'
printf '#!/bin/sh\necho "[  PASSED  ] 2 test(s)."\n' >"$tree/build/release/tests/test_b"
for jobs in 0 x -1; do
    PS_TEST_JOBS=$jobs expect_usage_error "PS_TEST_JOBS=$jobs" timeout 20 "$tree/tests/run-tests.sh"
done
expect_match "PS_TEST_JOBS message" "$cli_err" 'PS_TEST_JOBS must be a whole number'
# A runner that loses count of what it ran fails, whatever the tests said.
sed 's|^    count "\$log_dir/\$v-\$n.log" "\$rc"|    : count "$log_dir/$v-$n.log" "$rc"|' tests/run-tests.sh \
    >"$tree/tests/run-tests.sh"
grep -q '^    : count' "$tree/tests/run-tests.sh" && ok || bad "the runner's count line moved: fix this test's sed"
"$tree/tests/run-tests.sh" >"$cli_tmp/lost" 2>&1
rc=$?
[ $rc -ne 0 ] && ok || bad "a runner that counted none of its 10 tests exited 0"
expect_match "lost count named" "$(cat "$cli_tmp/lost")" 'runner: 0 of 10 tests ran'

cli_summary
