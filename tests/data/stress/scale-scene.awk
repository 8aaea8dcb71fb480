# scale.awk -v s=FACTOR: a .scn scaled by s about the origin: coordinates,
# edges, radii (objects, lights and the photon radii); powers by s^2 so that
# irradiance is unchanged. Comments are dropped.
function isnum(t) { return t ~ /^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$/ }
{
    sub(/#.*/, "")
    out = ""; next_n = 0; f = 1; radius_stmt = ($1 == "radius")
    for (i = 1; i <= NF; i++) {
        t = $i
        if (isnum(t) && (next_n > 0 || radius_stmt)) {
            t = sprintf("%.17g", t * (radius_stmt ? s : f)); if (next_n > 0) next_n--
        } else {
            next_n = 0
            if (t ~ /^(eye|target|corner|edge1|edge2|center|position)$/) { next_n = 3; f = s }
            if (i > 1 && t == "radius") { next_n = 1; f = s }
            if (t == "power") { next_n = 3; f = s * s }
        }
        out = out (i > 1 ? " " : "") t
    }
    print out
}
