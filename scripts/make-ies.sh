#!/usr/bin/env bash
# make-ies.sh: writes the bundled LM-63 photometric files of data/ies/, the
# project's own luminaires (nothing downloaded), each from a closed-form
# intensity so that tests can check what a renderer makes of them:
#   downlight-narrow.ies  LM-63-2002, rotationally symmetric (one horizontal
#                         angle): I = 2000 cd cos^24(theta), a beam of about 27
#                         degrees full width at half maximum, nothing above 90
#   batwing.ies           LM-63-1995, quadrant symmetric (0-90), TILT=INCLUDE:
#                         I = 400 cd cos(theta) (1 + 2.5 sin^2(theta))
#                         (1 + 0.3 cos(2 phi)), its peaks near 50 degrees off
#                         the nadir, brighter across the 0-180 plane
#   wallwasher.ies        LM-63-2019, no symmetry (0-360), thrown towards
#                         horizontal angle 0: I = 600 cd cos(theta)^0.5
#                         (0.25 + 0.75 max(0, cos phi) sin(theta)^0.5)
# Rerun after changing a formula: bash scripts/make-ies.sh [DIR]
set -euo pipefail
dir=${1:-data/ies}
mkdir -p "$dir"

# write FILE HEADER... : the header lines, then the numbers the awk program
# prints (line 10 onwards), eight to a line as LM-63 writers do.
emit() {
    local out=$1 prog=$2
    shift 2
    { printf '%s\r\n' "$@"; awk "$prog" | awk '{ for (i = 1; i <= NF; i++) { printf "%s%s", $i, (++n % 8 ? " " : "\r\n") } } END { if (n % 8) printf "\r\n" }'; } > "$out.tmp"
    mv "$out.tmp" "$out"
}

# The common shape of line 10 and 11: lamps, lumens/lamp (-1: absolute),
# multiplier, nv, nh, type C, metres, size; ballast, factor, watts.
emit "$dir/downlight-narrow.ies" 'BEGIN {
    pi = 3.14159265358979323846
    print "1 -1 1 19 1 1 2 0.1 0.1 0"
    print "1 1 15"
    for (i = 0; i <= 18; i++) printf "%g ", i * 5; print ""
    print "0"
    for (i = 0; i <= 18; i++) { t = i * 5 * pi / 180; c = cos(t); printf "%.4f ", (i == 18 ? 0 : 2000 * c ^ 24) }
    print ""
}' "IESNA:LM-63-2002" "[TEST] photosplat scripts/make-ies.sh" "[TESTLAB] photosplat" "[ISSUEDATE] 2026-12-01" \
   "[MANUFAC] photosplat (synthetic)" "[LUMCAT] PS-DL-NARROW" "[LUMINAIRE] narrow downlight, I = 2000 cos^24 cd" \
   "[LAMP] LED" "TILT=NONE"

emit "$dir/batwing.ies" 'BEGIN {
    pi = 3.14159265358979323846
    # TILT=INCLUDE: geometry 1, 3 angles, their factors (1 at the nadir aim)
    print "1 3 0 45 90 1 0.95 0.9"
    print "1 3000 1 19 5 1 2 0.6 0.6 0.05"
    print "1 1 40"
    for (i = 0; i <= 18; i++) printf "%g ", i * 5; print ""
    for (j = 0; j <= 4; j++) printf "%g ", j * 22.5; print ""
    for (j = 0; j <= 4; j++) {
        p = j * 22.5 * pi / 180
        for (i = 0; i <= 18; i++) { t = i * 5 * pi / 180; s = sin(t); printf "%.4f ", (i == 18 ? 0 : 400 * cos(t) * (1 + 2.5 * s * s) * (1 + 0.3 * cos(2 * p))) }
        print ""
    }
}' "IESNA:LM-63-1995" "[TEST] photosplat scripts/make-ies.sh" "[MANUFAC] photosplat (synthetic)" \
   "[LUMCAT] PS-BATWING" "[LUMINAIRE] batwing, I = 400 cos(t) (1 + 2.5 sin^2 t) (1 + 0.3 cos 2p) cd" "TILT=INCLUDE"

emit "$dir/wallwasher.ies" 'BEGIN {
    pi = 3.14159265358979323846
    print "1 -1 1 19 25 1 2 0.3 0.1 0.1"
    print "1 1 20"
    for (i = 0; i <= 18; i++) printf "%g ", i * 5; print ""
    for (j = 0; j <= 24; j++) printf "%g ", j * 15; print ""
    for (j = 0; j <= 24; j++) {
        p = j * 15 * pi / 180; cp = cos(p); if (cp < 0) cp = 0
        for (i = 0; i <= 18; i++) { t = i * 5 * pi / 180; printf "%.4f ", (i == 18 ? 0 : 600 * cos(t) ^ 0.5 * (0.25 + 0.75 * cp * sin(t) ^ 0.5)) }
        print ""
    }
}' "IES:LM-63-2019" "[TEST] photosplat scripts/make-ies.sh" "[TESTLAB] photosplat" "[ISSUEDATE] 2026-12-01" \
   "[MANUFAC] photosplat (synthetic)" "[LUMCAT] PS-WALLWASH" "[LUMINAIRE] asymmetric wall washer, thrown towards horizontal angle 0" \
   "[FILEGENINFO] computed from a closed form, not measured" "TILT=NONE"
echo "make-ies.sh: wrote $dir/downlight-narrow.ies $dir/batwing.ies $dir/wallwasher.ies"
