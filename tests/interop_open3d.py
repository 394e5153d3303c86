#!/usr/bin/python3
"""Open3D (Debian's python3-open3d) reads the scanner's files.
  interop_open3d.py CLOUD.ply EXPECTED_POINTS    a view: points, normals and colours, in mm
  interop_open3d.py --mesh SCAN_DIR              the fused mesh, as PLY and as OBJ"""
import sys
import numpy as np
import open3d as o3d

if sys.argv[1] == "--mesh":
    counts, verts = [], []
    for name in ("mesh.ply", "mesh.obj"):
        m = o3d.io.read_triangle_mesh(sys.argv[2] + "/" + name)
        assert len(m.triangles) > 10000, (name, len(m.triangles))
        assert m.has_vertex_colors() and m.has_vertex_normals(), name
        assert m.is_edge_manifold(), name + " is not edge-manifold"
        v = np.asarray(m.vertices)
        up = v[:, 2] if name == "mesh.ply" else v[:, 1]  # PLY keeps the object frame; OBJ is Y up
        assert up.min() > -4.0 and up.max() < 166.0, (name, up.min(), up.max())
        counts.append((len(m.vertices), len(m.triangles)))
        verts.append(v)
    assert counts[0] == counts[1], counts  # same mesh in both files
    # the OBJ is the PLY turned Y up: (x, y, z) -> (x, z, -y), vertex for vertex
    turned = np.stack([verts[0][:, 0], verts[0][:, 2], -verts[0][:, 1]], axis=1)
    assert np.abs(turned - verts[1]).max() < 1e-3, np.abs(turned - verts[1]).max()
    print("open3d %s read mesh.ply and mesh.obj: %d vertices, %d triangles, colours and normals"
          % (o3d.__version__, counts[0][0], counts[0][1]))
    sys.exit(0)

pcd = o3d.io.read_point_cloud(sys.argv[1])
pts = np.asarray(pcd.points)
assert len(pts) == int(sys.argv[2]), (len(pts), sys.argv[2])
assert pcd.has_normals() and pcd.has_colors()
n = np.linalg.norm(np.asarray(pcd.normals), axis=1)
assert np.all(np.abs(n - 1.0) < 1e-4)
# object frame, millimetres: the 150 mm object stands on the table (z from 0 to 150)
assert pts[:, 2].min() > -2.0 and pts[:, 2].max() < 152.0, (pts[:, 2].min(), pts[:, 2].max())
assert np.abs(pts[:, :2]).max() < 120.0
print("open3d %s read %d points with normals and colours" % (o3d.__version__, len(pts)))
