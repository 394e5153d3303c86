# An OFF mesh (OpenSCAD's export, z up) as an ASCII PLY triangle soup in the
# simulator's y-up convention (make measure-objects): each triangle gets its own three vertices,
# so that the simulator's vertex normals are the faces' own and a part's sharp edges stay sharp.
# Usage: awk -f tools/off2ply.awk part.off > part.ply
BEGIN { v = 0; f = 0; faces = 0 } # numbers, not "": the arrays are indexed by them
NR == 1 {
    if ($1 != "OFF") { print "off2ply: not an OFF file" > "/dev/stderr"; exit 1 }
    if (NF >= 3) { nv = $2 + 0; nf = $3 + 0; counted = 1 } # "OFF nv nf ne" on one line (OpenSCAD's)
    next
}
NF == 0 { next }
!counted { nv = $1 + 0; nf = $2 + 0; counted = 1; next }
v < nv { x[v] = $1; y[v] = $2; z[v] = $3; v++; next }
faces < nf { # a polygon as a fan: OpenSCAD writes polygons only for a lone primitive, whose
              # faces are convex, and triangles for anything made by its CSG
    if ($1 < 3 || NF < $1 + 1) { print "off2ply: a bad face: " $0 > "/dev/stderr"; exit 1 }
    for (j = 3; j <= $1; j++) { a[f] = $2; b[f] = $j; c[f] = $(j + 1); f++ }
    faces++
}
END {
    print "ply\nformat ascii 1.0\ncomment from OpenSCAD (data/objects)"
    print "element vertex " 3 * f "\nproperty float x\nproperty float y\nproperty float z"
    print "element face " f "\nproperty list uchar int vertex_indices\nend_header"
    for (i = 0; i < f; i++) {
        split(a[i] " " b[i] " " c[i], k, " ")
        for (j = 1; j <= 3; j++) print x[k[j]], z[k[j]], -y[k[j]] # (x, y, z) z up -> (x, z, -y)
    }
    for (i = 0; i < f; i++) print 3, 3 * i, 3 * i + 1, 3 * i + 2
}
