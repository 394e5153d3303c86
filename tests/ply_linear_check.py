#!/usr/bin/python3
"""A mesh.ply's colours (issue 34): most vertices' linear floats lie between two linear bytes
(the views' mean kept in 16 bits, not a byte), and every vertex's sRGB bytes are its linear
floats encoded (IEC 61966-2-1), within one level. Usage: ply_linear_check.py MESH.ply"""
import struct
import sys


def encode(x):
    e = 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055
    return 255.0 * e


def main(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").split("\n")
    vertices = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    want = ["x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "red_linear",
            "green_linear", "blue_linear"]
    props = [l.split()[-1] for l in header if l.startswith("property ") and "list" not in l]
    if props[:len(want)] != want or vertices < 1000:
        sys.exit(f"{path}: unexpected layout {props} or {vertices} vertices")
    between = worst = 0
    for i in range(vertices):
        v = struct.unpack_from("<6f3B3f", data, end + 39 * i)
        for k in range(3):
            lin = v[9 + k]
            between += abs(lin * 255.0 - round(lin * 255.0)) > 1e-3
            worst = max(worst, abs(v[6 + k] - encode(lin)))
    share = between / (3.0 * vertices)
    print(f"{path}: {share:.1%} of the linear values between two bytes; sRGB bytes within "
          f"{worst:.2f} of the encoding")
    if share < 0.5 or worst > 1.0:
        sys.exit(1)


if __name__ == "__main__":
    main(sys.argv[1])
