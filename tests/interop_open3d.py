#!/usr/bin/python3
"""Open3D (Debian's python3-open3d) reads a scanner PLY: points, normals and colours, with
positions on the scanned object's scale. Usage: interop_open3d.py FILE.ply EXPECTED_POINTS"""
import sys
import numpy as np
import open3d as o3d

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
