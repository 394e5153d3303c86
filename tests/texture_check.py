"""A scan's texture atlas as a reader sees it (tests/cli.sh): mesh.obj names mesh.mtl, which
names texture.png; the texture sampled where each face corner's vt puts it has the colour the
mesh's vertex has there (the two come from the same views: a vt pointing at another chart, or
at the texture upside down, gives another colour); mesh.glb holds the same PNG as its base
colour texture. Usage: python3 tests/texture_check.py SCAN_DIR. Prints the differences."""
import json
import struct
import sys

import numpy as np
import open3d as o3d

scan = sys.argv[1]
obj = open(f"{scan}/mesh.obj").read().splitlines()
assert "mtllib mesh.mtl" in obj and "usemtl scan" in obj, "mesh.obj names no material"
assert "map_Kd texture.png" in open(f"{scan}/mesh.mtl").read().splitlines(), "no texture named"
tex = np.asarray(o3d.io.read_image(f"{scan}/texture.png")).astype(float)
h, w = tex.shape[:2]

colours, uvs, corners = [], [], []
for line in obj:
    if line.startswith("v "):
        colours.append([float(x) for x in line.split()[4:7]])
    elif line.startswith("vt "):
        uvs.append([float(x) for x in line.split()[1:3]])
    elif line.startswith("f "):
        for c in line.split()[1:]:
            v, t, _ = c.split("/")
            corners.append((int(v) - 1, int(t) - 1))
colours = np.array(colours) * 255.0
uvs = np.array(uvs)
corners = np.array(corners)
assert len(uvs) >= len(colours), "fewer vt than vertices"

# bilinear, texel centres at +0.5; OBJ's v up from the bottom
x = uvs[corners[:, 1], 0] * w - 0.5
y = (1.0 - uvs[corners[:, 1], 1]) * h - 0.5
x0 = np.clip(np.floor(x).astype(int), 0, w - 2)
y0 = np.clip(np.floor(y).astype(int), 0, h - 2)
fx = np.clip(x - x0, 0, 1)[:, None]
fy = np.clip(y - y0, 0, 1)[:, None]
got = ((1 - fx) * (1 - fy) * tex[y0, x0] + fx * (1 - fy) * tex[y0, x0 + 1] +
       (1 - fx) * fy * tex[y0 + 1, x0] + fx * fy * tex[y0 + 1, x0 + 1])
diff = np.abs(got - colours[corners[:, 0]]).mean(axis=1)
median, p90 = np.percentile(diff, 50), np.percentile(diff, 90)
print(f"texture {w} x {h}, {len(corners)} corners: |texture - vertex colour| (sRGB levels) "
      f"median {median:.1f}, 90% {p90:.1f}")

data = open(f"{scan}/mesh.glb", "rb").read()
json_len, = struct.unpack_from("<I", data, 12)
gltf = json.loads(data[20:20 + json_len])
attributes = gltf["meshes"][0]["primitives"][0]["attributes"]
assert "TEXCOORD_0" in attributes and "COLOR_0" not in attributes, attributes
view = gltf["bufferViews"][gltf["images"][0]["bufferView"]]
start = 20 + json_len + 8 + view.get("byteOffset", 0)
png_in_glb = data[start:start + view["byteLength"]]
assert png_in_glb == open(f"{scan}/texture.png", "rb").read(), "mesh.glb's texture differs"
for m in gltf["materials"]:
    assert m["pbrMetallicRoughness"]["baseColorTexture"]["index"] == 0, m
print("mesh.glb: TEXCOORD_0 and texture.png as every material's base colour texture")
sys.exit(0 if median < 4.0 and p90 < 16.0 else 1)
