#!/usr/bin/env bash
# make-ring-obj.sh: writes data/scenes/ring.obj, the open ring of the
# ring-caustic bench scene: a thin cylindrical wall (inner radius R, wall
# T, height H) of N flat facets, with a top rim, centred on the origin,
# standing on y = 0. Facet normals face out of the wall's material, so the
# inner face looks toward the axis. Rerun after changing the numbers.
set -euo pipefail
out=${1:-data/scenes/ring.obj}
awk -v R=0.6 -v T=0.015 -v H=0.25 -v N=256 'BEGIN {
    pi = 3.14159265358979323846
    printf "# ring.obj: made by scripts/make-ring-obj.sh (R %g, T %g, H %g, N %d)\n", R, T, H, N
    # vertices: inner bottom, inner top, outer bottom, outer top, per segment
    for (i = 0; i < N; i++) {
        a = 2 * pi * i / N; c = cos(a); s = sin(a)
        printf "v %.7f 0 %.7f\nv %.7f %g %.7f\n", R * c, R * s, R * c, H, R * s
        printf "v %.7f 0 %.7f\nv %.7f %g %.7f\n", (R + T) * c, (R + T) * s, (R + T) * c, H, (R + T) * s
    }
    for (i = 0; i < N; i++) {
        j = (i + 1) % N
        ib = 4 * i + 1; it = ib + 1; ob = ib + 2; ot = ib + 3
        jb = 4 * j + 1; jt = jb + 1; pb = jb + 2; pt = jb + 3
        # inner face, normal toward the axis (counter-clockwise seen from inside)
        printf "f %d %d %d %d\n", ib, jb, jt, it
        # outer face, normal away from the axis
        printf "f %d %d %d %d\n", ob, ot, pt, pb
        # top rim, normal up
        printf "f %d %d %d %d\n", it, jt, pt, ot
    }
}' > "$out.tmp" && mv "$out.tmp" "$out"
