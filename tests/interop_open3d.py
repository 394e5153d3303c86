#!/usr/bin/python3
"""Open3D (Debian's python3-open3d) reads the scanner's files.
  interop_open3d.py CLOUD.ply EXPECTED_POINTS    a view: points, normals and colours, in mm
  interop_open3d.py --mesh SCAN_DIR              the fused mesh, as PLY and as OBJ"""
import sys
import numpy as np
import open3d as o3d

if sys.argv[1] == "--mesh":
    meshes = {}
    for name in ("mesh.ply", "mesh.obj"):
        m = o3d.io.read_triangle_mesh(sys.argv[2] + "/" + name, True)
        assert len(m.triangles) > 10000, (name, len(m.triangles))
        assert m.has_vertex_colors() and m.has_vertex_normals(), name
        assert m.is_edge_manifold(), name + " is not edge-manifold"
        v = np.asarray(m.vertices)
        up = v[:, 2] if name == "mesh.ply" else v[:, 1]  # PLY keeps the object frame; OBJ is Y up
        assert up.min() > -4.0 and up.max() < 166.0, (name, up.min(), up.max())
        meshes[name] = m
    ply, obj = meshes["mesh.ply"], meshes["mesh.obj"]
    assert len(ply.triangles) == len(obj.triangles), (len(ply.triangles), len(obj.triangles))
    # the same triangles in the same order; the OBJ is the PLY turned Y up: (x, y, z) -> (x, z, -y)
    # (a textured OBJ's vertex on a chart's border is read once for each of its texture places)
    pv = np.asarray(ply.vertices)[np.asarray(ply.triangles)]
    ov = np.asarray(obj.vertices)[np.asarray(obj.triangles)]
    turned = np.stack([pv[..., 0], pv[..., 2], -pv[..., 1]], axis=-1)
    assert np.abs(turned - ov).max() < 1e-3, np.abs(turned - ov).max()
    textured = obj.has_textures()
    if textured:  # its material's texture, and a place in it for each corner
        assert len(obj.triangle_uvs) == 3 * len(obj.triangles)
        uv = np.asarray(obj.triangle_uvs)
        assert uv.min() >= 0.0 and uv.max() <= 1.0, (uv.min(), uv.max())
    print("open3d %s read mesh.ply and mesh.obj%s: %d vertices, %d triangles, colours and normals"
          % (o3d.__version__, " (textured)" if textured else "", len(ply.vertices),
             len(ply.triangles)))
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
