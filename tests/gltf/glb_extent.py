"""Prints the extent of a GLB's positions from its JSON chunk (the POSITION accessor's min and max,
which the validator checks against the data): "height_m min_y_m", for tests/cli.sh.
Usage: python3 tests/gltf/glb_extent.py FILE.glb"""
import json
import struct
import sys

with open(sys.argv[1], "rb") as f:
    magic, version, length = struct.unpack("<4sII", f.read(12))
    chunk_len, chunk_type = struct.unpack("<I4s", f.read(8))
    assert magic == b"glTF" and version == 2 and chunk_type == b"JSON", "not a glTF 2.0 binary"
    doc = json.loads(f.read(chunk_len))
pos = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
print("%.4f %.4f" % (pos["max"][1] - pos["min"][1], pos["min"][1]))
