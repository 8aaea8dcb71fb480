#!/usr/bin/env bash
# fuzz.sh: builds the libFuzzer targets (mk/fuzz.mk) and runs each for a
# bounded time; `make fuzz` calls it. See docs/fuzzing.md.
#
#   FUZZ_SECONDS=60         seconds per target
#   FUZZ_TARGETS_RUN="scene obj png pfm ies exr"   which targets, in order
#   FUZZ_ARGS=""            more libFuzzer flags (e.g. -only_ascii=1)
#
# Prints one line per target (executions, findings) and exits 1 when any
# target found a crash, leak, timeout or out-of-memory input; those inputs are
# in build/fuzz/findings/TARGET/. The growing corpus is build/fuzz/corpus/.
set -euo pipefail
cd "$(dirname "$0")/.."

FUZZ_SECONDS=${FUZZ_SECONDS:-60}
FUZZ_TARGETS_RUN=${FUZZ_TARGETS_RUN:-"scene obj png pfm ies exr"}
FUZZ_ARGS=${FUZZ_ARGS:-}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
# Per input: 10 s is a hang (the readers take milliseconds); 2 GiB of memory
# is far beyond what any input up to max_len may legitimately cost.
TIMEOUT_S=10
RSS_LIMIT_MB=2048

# ---- packages: the project's, then clang and its libFuzzer runtime ----------
scripts/install-deps.sh --fuzz

make --no-print-directory -j"$JOBS" build-fuzz

# ---- per target: seeds, input size limit, dictionary ------------------------
seeds_of() {
    case $1 in
    scene) ls data/scenes/*.scn tests/data/good/*.scn tests/data/bad/*.scn ;;
    obj) ls tests/data/good/*.obj fuzz/seeds/obj/* ;;
    png) ls tests/data/golden/*.png fuzz/seeds/png/* ;;
    pfm) ls tests/data/golden/*.pfm fuzz/seeds/pfm/* ;;
    ies) ls data/ies/*.ies tests/data/ies-good/*.ies tests/data/ies-bad/*.ies ;;
    exr) ls fuzz/seeds/exr/* ;;
    esac
    # Earlier findings, kept as regression inputs.
    if [ -d "tests/data/fuzz/$1" ]; then find "tests/data/fuzz/$1" -type f; fi
}
# Big enough for every seed (the golden PFM is 48 KiB), small enough that
# each execution stays fast.
max_len_of() {
    case $1 in
    scene | obj | ies) echo 16384 ;;
    png | pfm | exr) echo 65536 ;;
    esac
}
dict_of() {
    case $1 in
    scene) echo fuzz/scene.dict ;;
    obj) echo fuzz/obj.dict ;;
    ies) echo fuzz/ies.dict ;;
    esac
}

mkdir -p build/fuzz/findings build/fuzz/logs
found_any=0
summary=()
for t in $FUZZ_TARGETS_RUN; do
    bin=build/fuzz/bin/fuzz_$t
    [ -x "$bin" ] || { echo "fuzz: no target '$t' (have: $(ls build/fuzz/bin | sed 's/^fuzz_//' | xargs))" >&2; exit 2; }
    seeds=build/fuzz/seeds/$t corpus=build/fuzz/corpus/$t findings=build/fuzz/findings/$t
    tmp=build/fuzz/tmp/$t log=build/fuzz/logs/$t.log
    rm -rf "$seeds" "$tmp"
    mkdir -p "$seeds" "$corpus" "$findings" "$tmp"
    seeds_of "$t" | while read -r f; do cp "$f" "$seeds/$(echo "$f" | tr / _)"; done
    dict=$(dict_of "$t")
    marker=build/fuzz/logs/$t.start
    touch "$marker"
    echo "fuzz: $t for ${FUZZ_SECONDS}s (log: $log)"
    # New inputs go to the first corpus folder; the seeds are only read.
    rc=0
    TMPDIR=$PWD/$tmp ASAN_OPTIONS="detect_leaks=1:abort_on_error=0" \
        "$bin" -max_total_time="$FUZZ_SECONDS" -max_len="$(max_len_of "$t")" -rss_limit_mb=$RSS_LIMIT_MB \
        -timeout=$TIMEOUT_S -print_final_stats=1 -artifact_prefix="$findings/" ${dict:+-dict=$dict} $FUZZ_ARGS \
        "$corpus" "$seeds" >"$log" 2>&1 || rc=$?
    rm -rf "$tmp"
    execs=$(grep -Eo 'stat::number_of_executed_units: [0-9]+' "$log" | grep -Eo '[0-9]+$' | tail -1)
    new=$(find "$findings" -type f -newer "$marker" \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' \
        -o -name 'oom-*' \) | sort)
    slow=$(find "$findings" -type f -newer "$marker" -name 'slow-unit-*' | wc -l)
    if [ -n "$new" ] || [ $rc -ne 0 ]; then
        found_any=1
        line=$(printf '%-6s %12s executions  FOUND: %s' "$t" "${execs:-?}" "$(echo $new | tr ' ' ',')")
        [ -z "$new" ] && line="$line (exit status $rc, see $log)"
        grep -E '^(==[0-9]+==ERROR|SUMMARY|fuzz: broken promise)' "$log" | head -3 | sed 's/^/    /' || true
    else
        line=$(printf '%-6s %12s executions  nothing found (corpus: %d inputs%s)' "$t" "${execs:-?}" \
            "$(find "$corpus" -type f | wc -l)" "$([ "$slow" -gt 0 ] && echo ", $slow slow" || true)")
    fi
    echo "$line"
    summary+=("$line")
done

echo "fuzz: summary (${FUZZ_SECONDS}s each)"
printf '  %s\n' "${summary[@]}"
if [ $found_any -ne 0 ]; then
    echo "fuzz: findings in build/fuzz/findings/: minimise one with" \
        "build/fuzz/bin/fuzz_TARGET -minimize_crash=1 -runs=10000 FILE, then save it under tests/data/fuzz/TARGET/" >&2
    exit 1
fi
