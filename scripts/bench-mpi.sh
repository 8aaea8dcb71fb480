#!/usr/bin/env bash
# bench-mpi.sh: photosplat-ref-mpi on the default scene (make bench runs it).
#  1. The split's overhead: 2 ranks x 1 thread against 1 process x 2 threads
#     (plain photosplat-ref), best of PS_BENCH_MPI_REPS (default 2) runs each,
#     alternated; goal: at least 0.9x the speed.
#  2. The phases of one rank x 1 thread (the work) and of 2 ranks (the
#     communication), and from them a model of the speedup at 8, 64 and 512
#     ranks (docs/reference-renderer.md explains it).
# Writes bench/results/mpi.txt as well as printing it.
set -u
cd "$(dirname "$0")/.."
scene=${SCENE:-data/scenes/cornell-caustic.scn}
reps=${PS_BENCH_MPI_REPS:-2}
out=bench/results/mpi.txt
if [ ! -x bin/photosplat-ref-mpi ] || ! command -v mpirun >/dev/null 2>&1; then
    echo "bench-mpi: skipped: no MPI (scripts/install-deps.sh installs Open MPI)"
    exit 0
fi
mpirun_=(mpirun --oversubscribe --bind-to none)
[ "$(id -u)" -eq 0 ] && mpirun_+=(--allow-run-as-root)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/bench-mpi.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

# key FILE NAME: a figure of a --stats file.
key() { sed -n "s/^ *\"$2\": *\([-0-9.e+]*\),*$/\1/p" "$1"; }
# wall CMD...: seconds the command took (it must succeed).
wall() {
    local t0 t1
    t0=$(date +%s.%N)
    "$@" >/dev/null 2>"$tmp/err" || { cat "$tmp/err" >&2; echo "bench-mpi: FAILED: $*" >&2; exit 1; }
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }'
}
min() { awk -v a="$1" -v b="$2" 'BEGIN { print (a == "" || b < a) ? b : a }'; }

{
echo "photosplat-ref-mpi on $(basename "$scene") (512x512, --quality default), $(nproc) cores"
best1= best2=
for i in $(seq "$reps"); do
    t=$(wall bin/photosplat-ref "$scene" -o "$tmp/a.png" --threads 2 --stats "$tmp/a.json")
    best1=$(min "$best1" "$t")
    t=$(wall "${mpirun_[@]}" -np 2 bin/photosplat-ref-mpi "$scene" -o "$tmp/b.png" --threads 1 --stats "$tmp/b.json")
    best2=$(min "$best2" "$t")
    cmp -s "$tmp/a.png" "$tmp/b.png" || { echo "bench-mpi: the images differ" >&2; exit 1; }
    echo "  run $i: 1 process x 2 threads: cache $(key "$tmp/a.json" cache_seconds) s of render $(key "$tmp/a.json" render_seconds) s; 2 ranks x 1 thread: cache $(key "$tmp/b.json" cache_seconds) s of render $(key "$tmp/b.json" render_seconds) s"
done
awk -v a="$best1" -v b="$best2" 'BEGIN {
    printf "overhead: 1 process x 2 threads %.2f s, 2 ranks x 1 thread %.2f s (wall, best of runs, mpirun start included): %.2fx the speed (goal >= 0.9x)\n", a, b, a / b }'
# The phases' work: one rank, one thread.
wall "${mpirun_[@]}" -np 1 bin/photosplat-ref-mpi "$scene" -o "$tmp/c.png" --threads 1 --stats "$tmp/c.json" >/dev/null
f1=$tmp/c.json f2=$tmp/b.json
awk -v trace="$(key $f1 dist_trace_seconds)" -v maps="$(key $f1 maps_seconds)" \
    -v lastmap="$(key $f1 dist_last_map_seconds)" -v cache="$(key $f1 cache_seconds)" \
    -v render="$(key $f1 render_seconds)" -v records="$(key $f1 cache_records)" \
    -v chunks="$(key $f1 dist_cache_chunks)" -v stored="$(($(key $f1 stored_caustic) + 2 * $(key $f1 stored_global)))" \
    -v merge2="$(key $f2 dist_merge_seconds)" -v xch2="$(key $f2 dist_cache_exchange_seconds)" \
    -v wait2="$(key $f2 dist_cache_wait_seconds)" -v cache2="$(key $f2 cache_seconds)" \
    -v trace2="$(key $f2 dist_trace_seconds)" -v tiles2="$(key $f2 dist_tiles_wait_seconds)" \
    -v bytes2="$(key $f2 dist_cache_bytes)" -v w=512 -v h=512 'BEGIN {
    # Work of one core (one rank, one thread).
    full = lastmap                      # the full map trace (for final gathering), part of maps
    serial = maps - lastmap             # kd-tree balancing of 3 maps + precomputed irradiance: on every rank
    image = render - cache
    tiles = int((w + 15) / 16) * int((h + 15) / 16)
    printf "phases of 1 rank x 1 thread: photon trace %.3f s (3 maps), kd-trees + irradiance %.3f s (replicated), cache %.3f s (%d records, %d chunks), image %.3f s (%d tiles)\n", trace, serial, cache, records, chunks, image, tiles
    printf "2 ranks x 1 thread: trace %.3f s a rank, map merge %.3f s (with waiting for the slower rank), cache %.3f s of which exchanges %.3f s (%.3f s waiting), %.0f kB of records, tile waits %.3f s\n", trace2, merge2, cache2, xch2, wait2, bytes2 / 1e3, tiles2
    # The model, per rank one core, on a cluster network of latency alpha and
    # bandwidth B (assumed: 2 us, 10 GB/s, an InfiniBand EDR class network):
    alpha = 2e-6; B = 10e9
    mbytes = stored * 26                # bytes of photons every rank receives (20 + material 2 + object 4)
    trec = cache / records              # a record: 1024 gather rays; the cache work is almost all records
    ttile = image / tiles
    printf "model (alpha %.0f us, B %.0f GB/s; merge %.1f MB; a record %.2f ms, a tile %.2f ms):\n", alpha * 1e6, B / 1e9, mbytes / 1e6, trec * 1e3, ttile * 1e3
    printf "%6s %8s %8s %8s %8s %8s %8s %9s  %s\n", "ranks", "trace", "merge", "serial", "cache", "image", "total", "speedup", "largest term"
    n1 = trace + serial + cache + image
    split(1 " " 2 " " 8 " " 64 " " 512, ns, " ")
    for (k = 1; k <= 5; k++) {
        n = ns[k]; lg = n > 1 ? log(n) / log(2) : 0
        t_trace = trace / n
        t_merge = n > 1 ? 3 * (2 * lg * alpha) + mbytes * (n - 1) / n / B : 0
        # cache: chunk by chunk; a chunk takes as long as its busiest rank
        # (ceil(records per chunk / n) records) plus one exchange.
        per = records / chunks; busy = int(per / n); if (busy < per / n) busy++
        t_cache = chunks * (busy * trec + (n > 1 ? 2 * lg * alpha + records / chunks * 230 / B : 0))
        # image: dynamic tiles; the last tile handed out ends the phase.
        t_image = (int(tiles / n) + (tiles % n ? 1 : 0)) * ttile
        tot = t_trace + t_merge + serial + t_cache + t_image
        worst = "serial"; wv = serial
        if (t_cache > wv) { worst = "cache"; wv = t_cache }
        if (t_image > wv) { worst = "image"; wv = t_image }
        if (t_merge > wv) { worst = "merge"; wv = t_merge }
        printf "%6d %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.1fx  %s\n", n, t_trace, t_merge, serial, t_cache, t_image, tot, n1 / tot, worst
        if (k == 5)
            printf "Amdahl limit of the replicated kd-trees + irradiance: %.0fx; the cache stops scaling at about %.0f ranks (its records per chunk), the image at %d (its tiles)\n", n1 / serial, records / chunks, tiles
    }
}'
} | tee "$out"
