# cli_lib.sh: helpers for the command-line tests (sourced). Each check counts a
# pass or a failure; cli_summary prints "cli: N passed, N failed".
cli_passed=0
cli_failed=0
cli_tmp=$(mktemp -d "${TMPDIR:-/tmp}/photosplat-cli.XXXXXX")
trap 'rm -rf "$cli_tmp"' EXIT

ok() { cli_passed=$((cli_passed + 1)); }
bad() { cli_failed=$((cli_failed + 1)); echo "FAIL: $*"; }

# expect_usage_error NAME CMD...: exit status 2, exactly one line on stderr,
# nothing on stdout. Leaves the stderr line in $cli_err.
expect_usage_error() {
    local name=$1
    shift
    "$@" >"$cli_tmp/out" 2>"$cli_tmp/err"
    local rc=$?
    cli_err=$(cat "$cli_tmp/err")
    local lines
    lines=$(wc -l <"$cli_tmp/err")
    if [ $rc -ne 2 ]; then
        bad "$name: exit status $rc, expected 2 (stderr: $cli_err)"
    elif [ "$lines" -ne 1 ]; then
        bad "$name: $lines lines on stderr, expected exactly 1: $cli_err"
    elif [ -s "$cli_tmp/out" ]; then
        bad "$name: printed to stdout on error"
    else
        ok
    fi
}

# expect_success NAME CMD...: exit status 0; stdout in $cli_out.
expect_success() {
    local name=$1
    shift
    "$@" >"$cli_tmp/out" 2>"$cli_tmp/err"
    local rc=$?
    cli_out=$(cat "$cli_tmp/out")
    if [ $rc -ne 0 ]; then
        bad "$name: exit status $rc: $(head -3 "$cli_tmp/err")"
    else
        ok
    fi
}

# expect_match NAME TEXT REGEX
expect_match() {
    if printf '%s\n' "$2" | grep -Eq -- "$3"; then ok; else bad "$1: '$2' does not match /$3/"; fi
}

cli_summary() {
    echo "cli: $cli_passed passed, $cli_failed failed"
    [ "$cli_failed" -eq 0 ]
}
