#!/usr/bin/env bash
# soak.sh: a long session of the preview window (make soak; minutes, not part
# of make test). Runs bin/photosplat under Xvfb with a generated, seeded script
# of random light and object moves, light power changes and camera orbits
# inside the default scene's box (each edit a selective repair of the maps,
# preview/repair.h), samples the window's resident memory (VmRSS) while it
# runs, and checks that
#   - memory stays flat: after the warm-up, the growth the Theil-Sen slope of
#     the whole RSS series gives over the session is within
#     SOAK_RSS_SLACK_MIB (8) or SOAK_RSS_SLACK_PERCENT (5) of the start, the
#     larger, or else not significant: under 3 standard errors of the slope
#     (from the residuals' MAD), so that noise alone never fails a run and two
#     runs in a row agree; the medians of the first and last thirds are
#     printed too;
#   - the picture stays right: every light and object is moved back at the end
#     and, with every photon of both caps drawn ("wait done"), the window
#     matches the screenshot taken the same way before the first move
#     (RMSE <= SOAK_RMSE); the screenshots in between are neither black nor
#     white;
#   - the window counted every move as an edit and ended without an error.
# Prints the RSS series (start, warm, end, max, per tenth) and a verdict;
# exits 1 when a check fails, 2 on a usage error. Knobs (environment):
#   SOAK_SECONDS (180) script time the moves are spread over; the session runs
#                longer by the waits for the caps (about a minute in all)
#   SOAK_MOVES (300)   moves; every SOAK_WAIT_EVERY-th (10) lets the maps reach
#                      their caps, every SOAK_SHOT_EVERY-th (50) screenshots too
#   SOAK_SEED (1)      the move sequence (the same seed, the same script)
#   SOAK_DIR (out/soak) where the script, RSS series, screenshots and stats stay
#   SOAK_BIN (bin)     the programs' folder
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_=${SOAK_SECONDS:-180}
MOVES=${SOAK_MOVES:-300}
SEED=${SOAK_SEED:-1}
DIR=${SOAK_DIR:-out/soak}
BIN=${SOAK_BIN:-bin}
WAIT_EVERY=${SOAK_WAIT_EVERY:-10}
SHOT_EVERY=${SOAK_SHOT_EVERY:-50}
SLACK_MIB=${SOAK_RSS_SLACK_MIB:-8}
SLACK_PERCENT=${SOAK_RSS_SLACK_PERCENT:-5}
# The first 15 % of the session (at least this many seconds) is warm-up:
# llvmpipe compiles its shaders and the allocator settles (about 10-20 s on a
# busy 2-core machine).
WARMUP_FRACTION=0.15
WARMUP_MIN_SECONDS=15
SAMPLE_SECONDS=0.5
# 8-bit screenshots of the same photons drawn the same way: bit-identical in
# practice; a little room for float blending order.
RMSE_MAX=${SOAK_RMSE:-0.004}
# A screenshot whose mean is outside this range is black or white: a lost
# picture (a NaN in a float layer turns a whole splat black or white).
MEAN_MIN=0.05
MEAN_MAX=0.95

scene=data/scenes/cornell-caustic.scn
win=$BIN/photosplat
compare=$BIN/photosplat-compare

usage() { echo "soak.sh: $1" >&2; exit 2; }
is_uint() { [[ $1 =~ ^[0-9]+$ ]] && [ "$1" -gt 0 ]; }
is_uint "$SECONDS_" || usage "SOAK_SECONDS '$SECONDS_' must be a whole number > 0"
is_uint "$MOVES" || usage "SOAK_MOVES '$MOVES' must be a whole number > 0"
is_uint "$WAIT_EVERY" || usage "SOAK_WAIT_EVERY '$WAIT_EVERY' must be a whole number > 0"
is_uint "$SHOT_EVERY" || usage "SOAK_SHOT_EVERY '$SHOT_EVERY' must be a whole number > 0"
[[ $SEED =~ ^[0-9]+$ ]] || usage "SOAK_SEED '$SEED' must be a whole number"
for p in "$win" "$compare"; do [ -x "$p" ] || usage "$p is missing (make bin/photosplat bin/photosplat-compare)"; done
command -v xvfb-run >/dev/null || usage "xvfb-run is missing (Debian package xvfb)"

rm -rf "$DIR"
mkdir -p "$DIR"
script=$DIR/script.txt

# ---- the script ---------------------------------------------------------------
# The default scene: a box x, z in [-1, 1], y in [0, 2]; light 0 a point light
# at (0, 1.9, 0); object 5 the glass sphere (centre 0.35 0.4 0.2, radius 0.4),
# object 6 the mirror sphere (-0.45 0.35 -0.4, radius 0.35). The light stays
# above the spheres and inside the box; each sphere's offset from its start
# stays in a box that keeps it inside the room and apart from the other one.
# Every tenth action or so is a camera orbit (small yaw and pitch steps, the
# pitch kept within +-30 degrees of the start, undone at the end) and some
# change the light's power (back to 100 W at the end).
awk -v seed="$SEED" -v moves="$MOVES" -v span="$SECONDS_" -v wait_every="$WAIT_EVERY" \
    -v shot_every="$SHOT_EVERY" -v dir="$DIR" '
function uniform(lo, hi) { return lo + (hi - lo) * rand() }
function r4(x) { return sprintf("%.4f", x) + 0 }  # what the script says is what the window adds
BEGIN {
    srand(seed)
    lx = 0; ly = 1.9; lz = 0                       # light 0 as the scene has it
    obj[0] = 5; obj[1] = 6
    xlo[0] = 0;    xhi[0] = 0.2                    # glass: may go right
    xlo[1] = -0.1; xhi[1] = 0                      # mirror: may go left
    for (k = 0; k < 2; k++) { ox[k] = oy[k] = oz[k] = 0 }
    t = 0.2
    printf "%.3f wait done\n%.3f screenshot %s/start.png\n", t, t, dir
    t = 1.0
    gap = span / moves
    yaw = 0; pitch = 0
    for (i = 1; i <= moves; i++) {
        if (rand() < 0.1) {
            dy = r4(uniform(-15, 15)); dp = r4(uniform(-5, 5))
            if (pitch + dp > 30 || pitch + dp < -30) dp = -dp
            printf "%.3f orbit %.4f %.4f\n", t, dy, dp
            yaw += dy; pitch += dp
        }
        if (rand() < 0.1) {
            printf "%.3f power light 0 %.2f %.2f %.2f\n", t, uniform(50, 150), uniform(50, 150), uniform(50, 150)
            powered = 1
            edits++
        }
        if (rand() < 0.6) {
            printf "%.3f move light 0 %.4f %.4f %.4f\n", t, uniform(-0.85, 0.85), uniform(1.2, 1.9), uniform(-0.85, 0.85)
        } else {
            k = rand() < 0.5 ? 0 : 1
            nx = r4(uniform(xlo[k], xhi[k])); ny = r4(uniform(0, 0.3)); nz = r4(uniform(-0.2, 0.2))
            printf "%.3f move object %d %.4f %.4f %.4f\n", t, obj[k], nx - ox[k], ny - oy[k], nz - oz[k]
            ox[k] = nx; oy[k] = ny; oz[k] = nz
        }
        if (i % wait_every == 0) printf "%.3f wait done\n", t
        if (i % shot_every == 0) printf "%.3f screenshot %s/move-%04d.png\n", t, dir, i
        t += gap * uniform(0.25, 1.75)   # bursts and pauses, mean gap span / moves
    }
    # Everything back where it started, then the same picture as at the start.
    printf "%.3f move light 0 0 1.9 0\n", t
    if (powered) { printf "%.3f power light 0 100 100 100\n", t; edits++ }
    # The camera back: pitch first, then yaw, the reverse of how it went
    # (the turntable orbit yaws about up, pitches about right).
    printf "%.3f orbit 0 %.4f\n%.3f orbit %.4f 0\n", t, -pitch, t, -yaw
    for (k = 0; k < 2; k++)
        printf "%.3f move object %d %.4f %.4f %.4f\n", t, obj[k], -ox[k], -oy[k], -oz[k]
    printf "%.3f wait done\n%.3f screenshot %s/end.png\n%.3f quit\n", t + 0.1, t + 0.2, dir, t + 0.3
    printf "%d\n", edits > (dir "/extra-edits.txt")
}' >"$script"
edits_expected=$((MOVES + 3 + $(cat "$DIR/extra-edits.txt")))

# ---- the session, sampled ------------------------------------------------------
pidfile=$DIR/window.pid
rss=$DIR/rss.tsv
echo "soak: $MOVES moves over ${SECONDS_} s of script (seed $SEED), $scene; RSS every ${SAMPLE_SECONDS} s into $rss"
t_start=$EPOCHREALTIME
# The window is started by a shell inside xvfb-run that writes its pid, so
# that /proc/PID is the window's own, not xvfb-run's or the X server's.
xvfb-run -a -s "-screen 0 1024x768x24" bash -c 'echo $$ >"$1"; shift; exec "$@"' _ "$pidfile" \
    "$win" "$scene" --size 256x256 --exposure 0.3 --overlay off --script "$script" --stats "$DIR/stats.json" \
    >"$DIR/window.out" 2>"$DIR/window.err" &
runner=$!
for _ in $(seq 100); do [ -s "$pidfile" ] && break; sleep 0.1; done
pid=$(cat "$pidfile" 2>/dev/null || true)
[ -n "$pid" ] || { kill "$runner" 2>/dev/null; echo "soak: FAIL: the window did not start" >&2; exit 1; }
: >"$rss"
while kill -0 "$pid" 2>/dev/null; do
    # seconds since the start, VmRSS and VmHWM in KiB
    awk -v now="$EPOCHREALTIME" -v t0="$t_start" '/^VmRSS:/ { r = $2 } /^VmHWM:/ { h = $2 }
        END { if (r) printf "%.2f\t%s\t%s\n", now - t0, r, h }' "/proc/$pid/status" >>"$rss" 2>/dev/null || true
    sleep "$SAMPLE_SECONDS"
done
set +e
wait "$runner"
rc=$?
set -e
wall=$(awk -v now="$EPOCHREALTIME" -v t0="$t_start" 'BEGIN { print now - t0 }')

# ---- verdict ---------------------------------------------------------------------
fails=0
fail() { echo "soak: FAIL: $*"; fails=$((fails + 1)); }
stat_of() { sed -n "s/.*\"$1\": \([^,]*\),*/\1/p" "$DIR/stats.json"; }
[ "$rc" = 0 ] || fail "the window exited with status $rc: $(head -c 500 "$DIR/window.err")"

printf 'session: %.1f s wall, ' "$wall"
if [ -s "$DIR/stats.json" ]; then
    printf '%s frames, %s edits, %.1f fps at the end, first frame after an edit: mean %.3f s, max %.3f s\n' \
        "$(stat_of frames)" "$(stat_of edits)" "$(stat_of fps)" "$(stat_of edit_to_frame_seconds_mean)" \
        "$(stat_of edit_to_frame_seconds_max)"
    printf 'photon maps at the end: %s + %s photons stored of caps %s + %s, %.1f MiB allocated, cap reached: %s\n' \
        "$(stat_of stored_caustic)" "$(stat_of stored_global)" "$(stat_of caustic_cap)" "$(stat_of global_cap)" \
        "$(awk -v b="$(stat_of photon_map_bytes)" 'BEGIN { print b / 1048576 }')" "$(stat_of cap_reached)"
    [ "$(stat_of edits)" = "$edits_expected" ] || fail "the window counted $(stat_of edits) edits, not $edits_expected"
else
    echo "no stats"
    fail "no stats file"
fi

# RSS: start, warm (first sample after the warm-up), end, max; the max of each
# tenth. Flat means: the Theil-Sen slope (the median of the slopes between
# samples half the series apart, which a few transient peaks cannot move) of
# the RSS after the warm-up, times the session's length, stays under the
# limit, or is not significant (under 3 standard errors: the residuals'
# MAD-scaled spread over sqrt(n) times the times' spread). llvmpipe's and the
# allocator's peaks come and go by tens of MiB between refreshes
# (docs/soak.md), while a leak raises the whole series. The medians of the
# first and last thirds and a least-squares line are printed, not judged.
# The last line the awk prints is the verdict: OK, or FAIL and why.
awk -F'\t' -v wf="$WARMUP_FRACTION" -v wmin="$WARMUP_MIN_SECONDS" -v slack="$SLACK_MIB" -v pct="$SLACK_PERCENT" '
    function sortv(v, k,    i, j, tmp) {
        for (i = 2; i <= k; i++) { tmp = v[i]; for (j = i - 1; j >= 1 && v[j] > tmp; j--) v[j + 1] = v[j]; v[j + 1] = tmp }
    }
    function median(lo, hi,    i, k, v) {
        k = 0
        for (i = lo; i <= hi; i++) v[++k] = r[i]
        sortv(v, k)
        return k % 2 ? v[(k + 1) / 2] : (v[k / 2] + v[k / 2 + 1]) / 2
    }
    function medianv(v, k) { sortv(v, k); return k % 2 ? v[(k + 1) / 2] : (v[k / 2] + v[k / 2 + 1]) / 2 }
    function maximum(lo, hi,    i, x) { x = 0; for (i = lo; i <= hi; i++) if (r[i] > x) x = r[i]; return x }
    { t[NR] = $1; r[NR] = $2 / 1024; hwm[NR] = $3 / 1024 }
    END {
        n = NR
        if (n < 12) { print "FAIL too few RSS samples (" n ")"; exit }
        warm = t[n] * wf; if (warm < wmin) warm = wmin
        w = 1; while (w < n && t[w] < warm) w++
        m = n - w + 1
        if (m < 9) { print "FAIL the session was shorter than its warm-up"; exit }
        third = int(m / 3)
        printf "RSS MiB: start %.1f (at %.1f s), warm %.1f (%.1f s), end %.1f (%.1f s), max %.1f, peak (VmHWM) %.1f; %d samples\n", r[1], t[1], r[w], t[w], r[n], t[n], maximum(1, n), hwm[n], n
        printf "RSS MiB, max of each tenth of the session:"
        for (d = 0; d < 10; d++) printf " %.1f", maximum(1 + int(d * n / 10), int((d + 1) * n / 10))
        printf "\n"
        # Theil-Sen over pairs half the series apart: m/2 slopes, O(m).
        h = int(m / 2); k = 0
        for (i = w; i + h <= n; i++) if (t[i + h] > t[i]) s_[++k] = (r[i + h] - r[i]) / (t[i + h] - t[i])
        slope = medianv(s_, k)
        for (i = w; i <= n; i++) tt[i - w + 1] = t[i]
        tmed = medianv(tt, m)
        for (i = w; i <= n; i++) rr[i - w + 1] = r[i] - slope * (t[i] - tmed)
        icpt = medianv(rr, m)
        for (i = w; i <= n; i++) { e = r[i] - (icpt + slope * (t[i] - tmed)); ad[i - w + 1] = e < 0 ? -e : e }
        sigma = 1.4826 * medianv(ad, m)
        st = 0; for (i = w; i <= n; i++) st += (t[i] - tmed) ^ 2
        se = sigma / sqrt(st > 0 ? st : 1)
        span = t[n] - t[w]
        growth = slope * span; noise = 3 * se * span
        a = median(w, w + third - 1); b = median(n - third + 1, n)
        limit = slack; if (a * pct / 100 > limit) limit = a * pct / 100
        printf "RSS after the warm-up (%.0f s on): Theil-Sen slope %+.4f MiB/s, %+.1f MiB over %.0f s (limit %.1f; 3 standard errors %.1f MiB; residual spread %.1f MiB)\n", t[w], slope, growth, span, limit, noise, sigma
        sx = sy = sxx = sxy = 0
        for (i = w; i <= n; i++) { sx += t[i]; sy += r[i]; sxx += t[i] * t[i]; sxy += t[i] * r[i] }
        ls = (m * sxy - sx * sy) / (m * sxx - sx * sx)
        printf "  not judged: median of the first third %.1f MiB, of the last third %.1f MiB (%+.1f); least-squares line %+.1f MiB\n", a, b, b - a, ls * span
        if (growth > limit && growth > noise) printf "FAIL memory grew: %+.1f MiB over the session by the Theil-Sen slope (limit %.1f MiB, noise %.1f MiB)\n", growth, limit, noise
        else print "OK"
    }' "$rss" >"$DIR/rss-summary.txt"
sed '$d' "$DIR/rss-summary.txt"
verdict=$(tail -n 1 "$DIR/rss-summary.txt")
[ "$verdict" = OK ] || fail "${verdict#FAIL }"

# The pictures.
mean_of() { "$compare" "$1" "$1" | sed -n 's/.*mean_a=\([^ ]*\).*/\1/p'; }
shopt -s nullglob
shots=("$DIR"/start.png "$DIR"/move-*.png "$DIR"/end.png)
shopt -u nullglob
for f in "${shots[@]}"; do
    if [ ! -s "$f" ]; then
        fail "no screenshot $f"
        continue
    fi
    mean=$(mean_of "$f")
    awk -v m="$mean" -v lo="$MEAN_MIN" -v hi="$MEAN_MAX" 'BEGIN { exit !(m >= lo && m <= hi) }' ||
        fail "$f is blank: mean $mean (expected $MEAN_MIN..$MEAN_MAX)"
done
echo "screenshots: ${#shots[@]}, means $(for f in "${shots[@]}"; do [ -s "$f" ] && printf '%s ' "$(mean_of "$f")"; done)"
if [ -s "$DIR/start.png" ] && [ -s "$DIR/end.png" ]; then
    line=$("$compare" "$DIR/end.png" "$DIR/start.png")
    rmse=$(sed -n 's/^rmse=\([^ ]*\).*/\1/p' <<<"$line")
    echo "back where it started, every photon drawn: $line"
    awk -v e="$rmse" -v m="$RMSE_MAX" 'BEGIN { exit !(e <= m) }' ||
        fail "the picture after moving everything back differs from the first: rmse $rmse (at most $RMSE_MAX)"
fi

if [ "$fails" -gt 0 ]; then
    echo "soak: FAIL ($fails problems; files in $DIR)"
    exit 1
fi
echo "soak: OK: memory flat and the picture unchanged after $edits_expected edits in $(printf '%.0f' "$wall") s (files in $DIR)"
