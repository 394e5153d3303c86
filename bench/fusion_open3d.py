#!/usr/bin/python3
"""Open3D's ScalableTSDFVolume on the depth maps bench-fusion wrote (the same views, poses, voxel
and truncation as the scanner's fusion), timed best of three, and the table of both.

    fusion_open3d.py DUMP_DIR "scanner VIEWS INTEGRATE_MS EXTRACT_MS VERTICES TRIANGLES"

Writes DUMP_DIR/open3d_mesh.ply for the accuracy comparison (mesh-compare against the truth).
Debian's python3-open3d (0.16); /usr/bin/python3, whose packages it is."""
import sys
import time

import numpy as np
import open3d as o3d


def main():
    dump, ours = sys.argv[1], sys.argv[2].split()
    lines = open(f"{dump}/poses.txt").read().split("\n")
    w, h, fx, fy, cx, cy, voxel, trunc, radius, bottom, top, views = [float(x) for x in lines[0].split()]
    w, h, views = int(w), int(h), int(views)
    intrinsic = o3d.camera.PinholeCameraIntrinsic(w, h, fx, fy, cx, cy)
    frames = []
    for v in range(views):
        e = np.eye(4)
        e[:3, :] = np.array([float(x) for x in lines[1 + v].split()]).reshape(3, 4)
        depth = np.fromfile(f"{dump}/view_{v}.depth", dtype=np.float32).reshape(h, w)
        rgb = np.fromfile(f"{dump}/view_{v}.rgb", dtype=np.uint8).reshape(h, w, 3)
        # millimetres throughout: depth_scale 1 keeps them, depth_trunc beyond any point
        rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
            o3d.geometry.Image(np.ascontiguousarray(rgb)), o3d.geometry.Image(depth),
            depth_scale=1.0, depth_trunc=1e5, convert_rgb_to_intensity=False)
        frames.append((rgbd, e))
    best_int, best_ext, mesh = 1e30, 1e30, None
    for _ in range(3):
        vol = o3d.pipelines.integration.ScalableTSDFVolume(
            voxel_length=voxel, sdf_trunc=trunc,
            color_type=o3d.pipelines.integration.TSDFVolumeColorType.RGB8)
        t0 = time.process_time()
        for rgbd, e in frames:
            vol.integrate(rgbd, intrinsic, e)
        t1 = time.process_time()
        mesh = vol.extract_triangle_mesh()
        t2 = time.process_time()
        best_int, best_ext = min(best_int, (t1 - t0) * 1e3), min(best_ext, (t2 - t1) * 1e3)
    o3d.io.write_triangle_mesh(f"{dump}/open3d_mesh.ply", mesh)
    our_int, our_ext = float(ours[2]), float(ours[3])
    print(f"fusion of {views} views on the same depth maps, voxel {voxel:g} mm, truncation "
          f"{trunc:g} mm (CPU ms, best of 3, one core: Open3D 0.16's own threads counted)")
    print("| | integrate | extract mesh | total | vertices | triangles |\n|---|---|---|---|---|---|")
    print(f"| Open3D ScalableTSDFVolume | {best_int:.0f} | {best_ext:.0f} | {best_int + best_ext:.0f} "
          f"| {len(mesh.vertices)} | {len(mesh.triangles)} |")
    print(f"| scanner (firmware/fusion.c) | {our_int:.0f} | {our_ext:.0f} | {our_int + our_ext:.0f} "
          f"| {ours[4]} | {ours[5]} |")
    print(f"| **scanner speed-up** | {best_int / our_int:.2f}x | {best_ext / our_ext:.2f}x | "
          f"**{(best_int + best_ext) / (our_int + our_ext):.2f}x** | | |")


if __name__ == "__main__":
    main()
