#!/usr/bin/env bash
# cli_compare.sh BIN_DIR: command-line tests of photosplat-compare: printed
# metrics on hand-made PNG and PFM files, and exit status 2 with one stderr
# line for every kind of bad input. Ends with "cli: N passed, N failed".
# VERBOSE=1 also prints each error message the program gave.
set -u

if [ $# -ne 1 ]; then
    echo "usage: $0 BIN_DIR" >&2
    exit 2
fi
CMP="$(cd "$1" && pwd)/photosplat-compare"
root="$(cd "$(dirname "$0")/.." && pwd)"
mkdir -p "$root/build/test-tmp"
tmp=$(mktemp -d "$root/build/test-tmp/cli_compare.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() {
    failed=$((failed + 1))
    echo "FAIL: $*"
}

# run ARGS...: runs the program, leaving rc, out and err.
run() {
    "$CMP" "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    out=$(cat "$tmp/out")
    err=$(cat "$tmp/err")
}

# expect_line NAME EXPECTED ARGS...: exit 0, exactly EXPECTED on stdout, nothing on stderr.
expect_line() {
    local name=$1 expected=$2
    shift 2
    run "$@"
    if [ $rc -eq 0 ] && [ "$out" = "$expected" ] && [ -z "$err" ] && [ "$(wc -l <"$tmp/out")" -eq 1 ]; then
        pass
    else
        fail "$name: rc=$rc stdout='$out' stderr='$err' (expected '$expected')"
    fi
}

# expect_fields NAME 'k=v k=v' ARGS...: exit 0 and each k=v appears as a field of the line.
expect_fields() {
    local name=$1 fields=$2
    shift 2
    run "$@"
    local ok=1 f
    for f in $fields; do
        case " $out " in *" $f "*) ;; *) ok=0 ;; esac
    done
    if [ $rc -eq 0 ] && [ $ok -eq 1 ] && [ -z "$err" ]; then
        pass
    else
        fail "$name: rc=$rc stdout='$out' stderr='$err' (expected fields '$fields')"
    fi
}

# expect_fail NAME NEEDLE ARGS...: exit 2, nothing on stdout, exactly one
# line on stderr, containing NEEDLE (a file name or the problem).
expect_fail() {
    local name=$1 needle=$2
    shift 2
    run "$@"
    local lines
    lines=$(wc -l <"$tmp/err")
    [ -n "${VERBOSE:-}" ] && echo "  $name: $err"
    if [ $rc -eq 2 ] && [ -z "$out" ] && [ "$lines" -eq 1 ] && [[ "$err" == *"$needle"* ]]; then
        pass
    else
        fail "$name: rc=$rc stdout='$out' stderr='$err' ($lines lines, expected status 2 and '$needle')"
    fi
}

# ---- hand-made images --------------------------------------------------------

# Little-endian binary32 of the values used below.
f32() {
    case $1 in
    0) printf '\x00\x00\x00\x00' ;;
    0.25) printf '\x00\x00\x80\x3e' ;;
    0.5) printf '\x00\x00\x00\x3f' ;;
    1) printf '\x00\x00\x80\x3f' ;;
    nan) printf '\x00\x00\xc0\x7f' ;;
    *) echo "f32: no bytes for $1" >&2; exit 2 ;;
    esac
}
# pfm FILE W H V...: an RGB PFM; V are samples, bottom row first.
pfm() {
    local file=$1 w=$2 h=$3
    shift 3
    {
        printf 'PF\n%s %s\n-1.0\n' "$w" "$h"
        for v in "$@"; do f32 "$v"; done
    } >"$file"
}

A=$tmp/a.pfm     # 2x1, all 0.5
B=$tmp/b.pfm     # 2x1, all 0.25
C=$tmp/c.pfm     # 2x1, left pixel 0.25, right 0.5
W=$tmp/w.pfm     # 2x1, left white, right black (linear 1 and 0)
Z=$tmp/z.pfm     # 2x1, all 0 (a mask that selects nothing)
N=$tmp/nan.pfm   # 2x1, a NaN in the right pixel's green
S=$tmp/small.pfm # 3x1
pfm "$A" 2 1 0.5 0.5 0.5 0.5 0.5 0.5
pfm "$B" 2 1 0.25 0.25 0.25 0.25 0.25 0.25
pfm "$C" 2 1 0.25 0.25 0.25 0.5 0.5 0.5
pfm "$W" 2 1 1 1 1 0 0 0
pfm "$Z" 2 1 0 0 0 0 0 0
pfm "$N" 2 1 0.5 0.5 0.5 0.5 nan 0.5
pfm "$S" 3 1 0 0 0 0 0 0 0 0 0

# Two 2x1 8-bit RGB PNGs (signature, IHDR, one IDAT, IEND), written once by
# ps_png_write and stripped of their gAMA/sRGB/cHRM chunks to keep them short:
#   M: left pixel white (255), right black (0)
#   G: both pixels grey code 128 (linear 0.2158605)
png_head='\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\x00\x02\x00\x00\x00\x01\x08\x02\x00\x00\x00\x7b\x40\xe8\xdd'
png_tail='\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82'
M=$tmp/m.png
G=$tmp/g.png
printf "$png_head"'\x00\x00\x00\x0f\x49\x44\x41\x54\x08\x99\x63\xf8\xff\xff\x3f\x03\x03\x03\x00\x0e\xf8\x02\xfe\x4b\x74\x37\x34'"$png_tail" >"$M"
printf "$png_head"'\x00\x00\x00\x0f\x49\x44\x41\x54\x08\x99\x63\x6c\x68\x68\x60\x60\x60\x00\x00\x07\x8e\x01\x82\x67\x59\xc1\x85'"$png_tail" >"$G"

# Magic, not the name, decides the format.
cp "$W" "$tmp/w-really-pfm.png"
cp "$M" "$tmp/m-really-png.pfm"

# Broken inputs.
: >"$tmp/empty.pfm"
printf 'this is not an image\n' >"$tmp/garbage.png"
head -c 20 "$A" >"$tmp/truncated.pfm"
head -c 40 "$M" >"$tmp/truncated.png"
mkdir "$tmp/dir.png"

# ---- metrics -----------------------------------------------------------------

# Every sample differs by 0.25: rmse 0.25, relmse 0.0625/0.0725, psnr 10·log10(16).
expect_line "uniform difference" "rmse=0.25 relmse=0.862069 psnr=12.0412 mean_a=0.5 mean_b=0.25" "$A" "$B"
# B is the reference: relmse = 0.0625/(0.25+0.01).
expect_line "reference is B" "rmse=0.25 relmse=0.240385 psnr=12.0412 mean_a=0.25 mean_b=0.5" "$B" "$A"
expect_line "identical" "rmse=0 relmse=0 psnr=inf mean_a=0.5 mean_b=0.5" "$A" "$A"
# Half the samples differ by 0.25: mse 0.03125.
expect_fields "half differs" "rmse=0.176777 mean_b=0.375" "$A" "$C"
# The mask keeps the left pixel only: as the uniform case.
expect_line "mask left" "rmse=0.25 relmse=0.862069 psnr=12.0412 mean_a=0.5 mean_b=0.25" "$A" "$C" --mask "$M"
expect_line "mask option first, =form" "rmse=0.25 relmse=0.862069 psnr=12.0412 mean_a=0.5 mean_b=0.25" --mask="$M" "$A" "$C"
# PNG against PNG: encoded values, white 1 and black 0.
expect_line "png identical" "rmse=0 relmse=0 psnr=inf mean_a=0.5 mean_b=0.5" "$M" "$M"
expect_fields "png encoded" "mean_a=0.501961 mean_b=0.5" "$G" "$M"
# --linear decodes PNG: code 128 is linear 0.2158605, and against (1, 0):
# mse = (0.784140² + 0.215861²)/2 = 0.330735, rmse 0.575096.
expect_fields "png linear" "rmse=0.575096 mean_a=0.215861 mean_b=0.5" "$G" "$M" --linear
# PNG against PFM: always linear.
expect_fields "mixed formats decode" "mean_a=0.215861 mean_b=0.5" "$G" "$A"
expect_line "mixed formats equal" "rmse=0 relmse=0 psnr=inf mean_a=0.5 mean_b=0.5" "$M" "$W"
expect_line "magic not name" "rmse=0 relmse=0 psnr=inf mean_a=0.5 mean_b=0.5" "$tmp/m-really-png.pfm" "$tmp/w-really-pfm.png"

# ---- help --------------------------------------------------------------------

run --help
if [ $rc -eq 0 ] && [[ "$out" == *"usage: photosplat-compare"* ]] && [[ "$out" == *"--mask"* ]] &&
    [[ "$out" == *"linear"* ]] && [ -z "$err" ]; then
    pass
else
    fail "--help: rc=$rc stderr='$err'"
fi

# ---- bad input: status 2, one line on stderr naming the file or problem ------

expect_fail "no arguments" "two images" 
expect_fail "one argument" "two images" "$A"
expect_fail "three arguments" "'$B'" "$A" "$A" "$B"
expect_fail "unknown option" "--frobnicate" "$A" "$B" --frobnicate
expect_fail "mask without value" "--mask" "$A" "$B" --mask
expect_fail "mask twice" "--mask" "$A" "$B" --mask "$M" --mask "$M"
expect_fail "flag with value" "--linear" "$A" "$B" --linear=yes
expect_fail "missing file" "$tmp/missing.pfm" "$A" "$tmp/missing.pfm"
expect_fail "missing mask" "$tmp/missing.png" "$A" "$B" --mask "$tmp/missing.png"
expect_fail "directory" "$tmp/dir.png" "$tmp/dir.png" "$A"
expect_fail "garbage file" "$tmp/garbage.png" "$A" "$tmp/garbage.png"
expect_fail "empty file" "$tmp/empty.pfm" "$tmp/empty.pfm" "$A"
expect_fail "truncated PFM" "$tmp/truncated.pfm" "$A" "$tmp/truncated.pfm"
expect_fail "truncated PNG" "$tmp/truncated.png" "$tmp/truncated.png" "$M"
expect_fail "size mismatch" "3x1" "$A" "$S"
expect_fail "mask size mismatch" "$S" "$A" "$B" --mask "$S"
expect_fail "mask selects nothing" "$Z" "$A" "$B" --mask "$Z"
expect_fail "NaN pixel" "$N: pixel (1, 0)" "$N" "$A"
expect_fail "NaN in reference" "$N" "$A" "$N"

echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
