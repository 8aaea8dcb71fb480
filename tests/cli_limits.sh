#!/usr/bin/env bash
# cli_limits.sh BIN_DIR: limits that refuse cleanly, outputs that appear whole
# or not at all, and interruption (docs/limits.md). Every refusal is one line
# on stderr and exit status 2, before any output file exists; PS_MEMORY_LIMIT
# lowers the memory budget so that no check needs gigabytes; SIGINT and
# SIGTERM stop a run with 130 / 143 and nothing written.
set -u
cd "$(dirname "$0")/.."
bin=${1:-bin}
. tests/cli_lib.sh
ref=$bin/photosplat-ref
snap=$bin/photosplat-snap
info=$bin/photosplat-info
cmp=$bin/photosplat-compare
win=$bin/photosplat
scene=data/scenes/cornell-caustic.scn
small=(--caustic-photons 2000 --global-photons 1000)
out=$cli_tmp/results # ($cli_tmp/out is cli_lib.sh's)
mkdir -p "$out"

# nothing_left NAME: no file at all in $out (no result, no temporary file).
nothing_left() {
    local left
    left=$(ls -A "$out")
    if [ -z "$left" ]; then ok; else bad "$1: left behind: $left"; fi
    rm -rf "${out:?}"/* 2>/dev/null
}

# ---- memory: photon counts and image sizes that would not fit ------------------
export PS_MEMORY_LIMIT=64M
expect_usage_error "ref photons over budget" "$ref" "$scene" -o "$out/a.png" --caustic-photons 10000000
expect_match "ref photons message" "$cli_err" \
    '^photosplat-ref: 10[0-9]+ photons and a 512x512 image would need [0-9]+ MiB, more than the memory budget of 64 MiB \(set by PS_MEMORY_LIMIT\)$'
nothing_left "ref photons over budget"
expect_usage_error "ref image over budget" "$ref" "$scene" -o "$out/a.png" --size 16384x16384 "${small[@]}"
expect_match "ref image message" "$cli_err" 'a 16384x16384 image would need 9\.3 GiB, more than the memory budget'
nothing_left "ref image over budget"
expect_usage_error "snap image over budget" "$snap" "$scene" -o "$out/a.png" --size 4000x4000 "${small[@]}"
expect_match "snap image message" "$cli_err" '^photosplat-snap: .*4000x4000 image would need'
nothing_left "snap image over budget"
expect_usage_error "window over budget" env -u DISPLAY "$win" "$scene" --size 8000x8000
expect_match "window message" "$cli_err" '^photosplat: .*8000x8000 image would need'
# The tracer's cap: the plan counts one stored photon per emitted one, the
# global map stores several; the cap stops it before the map grows past it.
PS_MEMORY_LIMIT=8M expect_usage_error "photon map cap" "$ref" "$scene" --photons-only --caustic-photons 0 \
    --global-photons 100000 --dump-photons "$out/d.txt"
expect_match "cap message" "$cli_err" 'the global photon map would hold more than [0-9]+ photons, the most the memory budget allows'
nothing_left "photon map cap"
# A PNG whose header promises 8000x8000 pixels: refused before its pixels are read.
python3 - "$cli_tmp/big.png" <<'EOF'
import struct, sys, zlib
def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
ihdr = struct.pack('>IIBBBBB', 8000, 8000, 8, 2, 0, 0, 0)
open(sys.argv[1], 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', ihdr) + chunk(b'IDAT', zlib.compress(b'\0' * 64)) + chunk(b'IEND', b''))
EOF
expect_usage_error "compare image over budget" "$cmp" "$cli_tmp/big.png" "$cli_tmp/big.png"
expect_match "compare message" "$cli_err" 'big\.png: image is 8000x8000: it would need 1\.2 GiB, more than the memory budget of 64 MiB'
unset PS_MEMORY_LIMIT
# Without PS_MEMORY_LIMIT the budget is 3/4 of physical memory: 10^9 photons
# (70 GiB) do not fit on a machine of up to 94 GiB.
mem_kib=$(awk '/^MemTotal:/ { print $2 }' /proc/meminfo)
if [ "${mem_kib:-0}" -lt $((94 * 1024 * 1024)) ]; then
    expect_usage_error "10^9 photons" "$ref" "$scene" -o "$out/a.png" --caustic-photons 1000000000
    expect_match "physical budget" "$cli_err" 'would need 70\.[0-9] GiB, more than the memory budget of [0-9.]+ GiB \(75 % of physical memory\)$'
    nothing_left "10^9 photons"
fi

# ---- absurd scenes ---------------------------------------------------------------
# An OBJ of 20000 faces against a 4 MiB budget: refused after counting, before parsing.
awk 'BEGIN { for (i = 0; i <= 100; i++) for (j = 0; j <= 100; j++) printf "v %d 0 %d\n", i, j;
             for (i = 0; i < 100; i++) for (j = 0; j < 100; j++) { a = i * 101 + j + 1;
                 printf "f %d %d %d\nf %d %d %d\n", a, a + 1, a + 102, a, a + 102, a + 101 } }' >"$cli_tmp/grid.obj"
printf 'camera eye 50 50 150 target 50 0 50 up 0 1 0 fov 40\nmesh grid.obj\nlight point position 50 20 50 power 1 1 1\n' \
    >"$cli_tmp/grid.scn"
PS_MEMORY_LIMIT=4M expect_usage_error "OBJ over budget" "$info" "$cli_tmp/grid.scn"
expect_match "OBJ message" "$cli_err" 'grid\.scn:2: mesh: .*grid\.obj: 20000 faces would need 10 MiB, more than the memory budget of 4 MiB'
# 100 spheres are exact for the ray tracer but 980 000 triangles for the preview.
{
    printf 'camera eye 0 5 30 target 0 0 0 up 0 1 0 fov 40\nlight point position 0 20 0 power 1 1 1\n'
    for i in $(seq 0 99); do printf 'sphere center %d 0 %d radius 0.4\n' $((i % 10)) $((i / 10)); done
} >"$cli_tmp/spheres.scn"
PS_MEMORY_LIMIT=64M expect_success "spheres fit the ray tracer" "$ref" "$cli_tmp/spheres.scn" --photons-only "${small[@]}"
PS_MEMORY_LIMIT=64M expect_usage_error "spheres' preview mesh" "$snap" "$cli_tmp/spheres.scn" -o "$out/a.png" "${small[@]}"
expect_match "mesh message" "$cli_err" 'spheres\.scn: the preview mesh of 980000 triangles would need 146 MiB, more than the memory budget of 64 MiB'
nothing_left "spheres' preview mesh"
# 20 area lights are 320 GL lights with shadow maps: refused; without shadows they fit.
{
    printf 'camera eye 0 1 3.4 target 0 1 0 up 0 1 0 fov 40\nquad corner -1 0 -1 edge1 0 0 2 edge2 2 0 0\n'
    for i in $(seq 0 19); do printf 'light quad corner %d 1.9 0 edge1 0.1 0 0 edge2 0 0 0.1 power 1 1 1\n' "$i"; done
} >"$cli_tmp/lights.scn"
PS_MEMORY_LIMIT=512M expect_usage_error "GL lights' shadow maps" "$snap" "$cli_tmp/lights.scn" -o "$out/a.png" \
    --size 32x32 "${small[@]}"
expect_match "lights message" "$cli_err" 'lights\.scn: 20 lights \(320 GL lights, [0-9]+ shadow maps of 1024x1024\) would need [0-9.]+ GiB'
nothing_left "GL lights' shadow maps"
PS_MEMORY_LIMIT=512M expect_success "lights without shadows" "$snap" "$cli_tmp/lights.scn" -o "$out/a.png" \
    --size 32x32 --shadows off "${small[@]}"
rm -f "$out/a.png"
# More lights than the scene format's limit.
{
    printf 'camera eye 0 1 3.4 target 0 1 0 up 0 1 0 fov 40\n'
    awk 'BEGIN { for (i = 0; i <= 100000; i++) print "light point position 0 1 0 power 1 1 1" }'
} >"$cli_tmp/many.scn"
expect_usage_error "100001 lights" "$info" "$cli_tmp/many.scn"
expect_match "lights limit" "$cli_err" 'many\.scn:100002: more than 100000 lights'

# ---- inputs that are not files -----------------------------------------------------
mkfifo "$cli_tmp/fifo"
mkdir -p "$cli_tmp/dir.scn" "$cli_tmp/dir.obj"
expect_usage_error "scene is a directory" "$ref" "$cli_tmp/dir.scn" --photons-only
expect_match "directory message" "$cli_err" 'dir\.scn: is a directory, not a file'
expect_usage_error "scene is /dev/zero" timeout 20 "$info" /dev/zero
expect_match "device message" "$cli_err" '^/dev/zero: not a regular file'
expect_usage_error "scene is a FIFO" timeout 20 "$info" "$cli_tmp/fifo"
expect_match "FIFO message" "$cli_err" 'fifo: not a regular file'
for target in dir.obj /dev/zero fifo; do
    printf 'camera eye 0 1 3 target 0 1 0 up 0 1 0 fov 40\nlight point position 0 1 0 power 1 1 1\nmesh %s\n' \
        "$target" >"$cli_tmp/m.scn"
    expect_usage_error "OBJ is $target" timeout 20 "$info" "$cli_tmp/m.scn"
    expect_match "OBJ $target message" "$cli_err" 'm\.scn:3: mesh: .*(is a directory|not a regular file)'
done
# An MTL that is a FIFO: a warning (the OBJ reader's: its materials fall back to the default), no hang.
printf 'mtllib fifo\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$cli_tmp/tri.obj"
printf 'camera eye 0 1 3 target 0 1 0 up 0 1 0 fov 40\nlight point position 0 1 0 power 1 1 1\nmesh tri.obj\n' \
    >"$cli_tmp/t.scn"
timeout 20 "$info" "$cli_tmp/t.scn" >/dev/null 2>"$cli_tmp/err"
rc=$?
[ $rc -eq 0 ] || [ $rc -eq 2 ] && ok || bad "MTL FIFO: exit status $rc (124 is a hang)"
expect_match "MTL FIFO named" "$(cat "$cli_tmp/err")" "material library 'fifo'"
expect_usage_error "compare a directory" "$cmp" "$cli_tmp" "$cli_tmp/big.png"
expect_usage_error "compare /dev/zero" timeout 20 "$cmp" /dev/zero "$cli_tmp/big.png"
expect_usage_error "compare a FIFO" timeout 20 "$cmp" "$cli_tmp/fifo" "$cli_tmp/big.png"
expect_match "compare FIFO message" "$cli_err" 'fifo: not a regular file'
expect_usage_error "mask a FIFO" timeout 20 "$cmp" "$cli_tmp/big.png" "$cli_tmp/big.png" --mask "$cli_tmp/fifo"

# ---- outputs that cannot be written: refused before any work --------------------
expect_usage_error "missing directory" "$ref" "$scene" -o "$out/none/a.png"
expect_match "missing directory message" "$cli_err" '^.*/none/a\.png: cannot create: No such file or directory$'
expect_usage_error "output is a directory" "$ref" "$scene" -o "$out"
expect_match "directory output message" "$cli_err" 'results: is a directory, cannot write a file there$'
expect_usage_error "stats in a read-only place" "$ref" "$scene" --photons-only --stats /proc/ps-stats.json
expect_match "read-only message" "$cli_err" '^/proc/ps-stats\.json: cannot create'
expect_usage_error "dump is a directory" "$snap" "$scene" --dump-photons "$out" -o "$out/a.png"
expect_usage_error "hdr in a missing directory" "$snap" "$scene" --hdr "$out/none/a.pfm"
expect_usage_error "window stats" env -u DISPLAY "$win" "$scene" --stats "$out/none/s.json"
expect_match "window stats message" "$cli_err" 'none/s\.json: cannot create'
printf '0.5 screenshot %s\n1 quit\n' "$out/none/shot.png" >"$cli_tmp/shot.txt"
expect_usage_error "window screenshot path" env -u DISPLAY "$win" "$scene" --script "$cli_tmp/shot.txt"
expect_match "screenshot message" "$cli_err" 'none/shot\.png: cannot create'
if [ "$(id -u)" -ne 0 ]; then # root writes anywhere
    mkdir -p "$cli_tmp/ro" && chmod 555 "$cli_tmp/ro"
    expect_usage_error "read-only directory" "$ref" "$scene" -o "$cli_tmp/ro/a.png"
    expect_match "permission message" "$cli_err" 'cannot create: Permission denied'
fi
# A FIFO nobody reads: refused at once, not a hang.
expect_usage_error "FIFO without a reader" timeout 20 "$ref" "$scene" --photons-only --stats "$cli_tmp/fifo" "${small[@]}"
expect_match "FIFO output message" "$cli_err" 'fifo: cannot open: No such device or address'
nothing_left "unwritable outputs"

# ---- writes that fail midway leave nothing ------------------------------------------
expect_usage_error "/dev/full" "$ref" "$scene" --hdr /dev/full --size 16x16 --spp 1 "${small[@]}"
expect_match "/dev/full message" "$cli_err" '^/dev/full: write failed: No space left on device$'
# A file-size limit of 64 KiB cuts a 786 KiB PFM and 2 MiB photon dump midway.
(ulimit -f 64 && "$ref" "$scene" --hdr "$out/a.pfm" --size 256x256 --spp 1 "${small[@]}" >/dev/null 2>"$cli_tmp/err")
rc=$?
[ $rc -eq 2 ] && ok || bad "file-size limit: exit status $rc, expected 2"
expect_match "file too large" "$(cat "$cli_tmp/err")" 'a\.pfm: write failed: File too large'
nothing_left "PFM cut by a file-size limit"
(ulimit -f 64 && "$ref" "$scene" --photons-only --caustic-photons 20000 --dump-photons "$out/d.txt" >/dev/null 2>"$cli_tmp/err")
rc=$?
[ $rc -eq 2 ] && ok || bad "dump cut: exit status $rc, expected 2"
nothing_left "photon dump cut by a file-size limit"

# ---- SIGINT and SIGTERM ---------------------------------------------------------------
# interrupt NAME SIGNAL STATUS REGEX CMD...: starts CMD, sends SIGNAL after
# 2 s, expects STATUS, the one line REGEX and nothing in $out. Each run is
# minutes long even on 16 cores (the renderer checks the flag every pixel
# row, the tracer every 1024 photons, so they stop at once); PS_MEMORY_LIMIT
# lets the plan of 5·10^8 photons pass on any machine.
interrupt() {
    local name=$1 sig=$2 want=$3 re=$4
    shift 4
    "$@" >/dev/null 2>"$cli_tmp/err" &
    local pid=$!
    sleep 2
    kill -"$sig" $pid
    wait $pid
    local rc=$?
    if [ $rc -ne "$want" ]; then bad "$name: exit status $rc, expected $want: $(cat "$cli_tmp/err")"; else ok; fi
    expect_match "$name message" "$(cat "$cli_tmp/err")" "$re"
    nothing_left "$name"
}
# (Under the sanitizers in a loaded suite, 2 s may still be the irradiance
# precomputation, which says so.)
interrupt "ref SIGINT" INT 130 \
    '^photosplat-ref: interrupted (after [0-9]+ % of the (image|caustic photons|global photons)|while precomputing irradiance); nothing written$' \
    "$ref" "$scene" -o "$out/a.png" --hdr "$out/a.pfm" --stats "$out/s.json" --dump-photons "$out/d.txt" \
    --size 512x512 --spp 1024
interrupt "ref SIGTERM" TERM 143 '^photosplat-ref: interrupted after [0-9]+ % of the global photons; nothing written$' \
    env PS_MEMORY_LIMIT=64G "$ref" "$scene" --photons-only --stats "$out/s.json" --caustic-photons 0 \
    --global-photons 500000000
interrupt "snap SIGINT" INT 130 '^photosplat-snap: interrupted after [0-9.]+ s of 60\.0 s; nothing written$' \
    "$snap" "$scene" -o "$out/a.png" --size 64x64 --time 60 --caustic-photons 20000000

cli_summary
