#!/usr/bin/env python3
"""Rewrite an ASCII PLY (float vertex properties, 'list uchar int' faces) as binary little-endian.

How data/bunny/*.ply were made from the Stanford 3D Scanning Repository's ASCII files:
    scripts/ply-ascii-to-binary.py bun_zipper.ply data/bunny/bun_zipper.ply
Each value is rounded to float32 once, as the simulator's reader does with the ASCII text
((float)strtod), so a scan of the binary file is byte for byte a scan of the ASCII one.
"""
import struct
import sys


def convert(src, dst):
    with open(src, "rb") as f:
        lines = f.read().split(b"\n")
    header, body_start = [], 0
    for i, line in enumerate(lines):
        header.append(line.rstrip(b"\r"))
        if line.strip() == b"end_header":
            body_start = i + 1
            break
    elements = []  # [name, count, [property lines]]
    for h in header:
        words = h.split()
        if words[:1] == [b"element"]:
            elements.append([words[1], int(words[2]), []])
        elif words[:1] == [b"property"]:
            elements[-1][2].append(words[1:])
    out = bytearray()
    for h in header:
        out += (b"format binary_little_endian 1.0" if h.startswith(b"format") else h) + b"\n"
    row = body_start
    for name, count, props in elements:
        for _ in range(count):
            values = lines[row].split()
            row += 1
            k = 0
            for p in props:
                if p[0] == b"list":
                    if p[1:3] != [b"uchar", b"int"]:
                        sys.exit(f"{src}: list {p[1:3]} not handled")
                    n = int(values[k])
                    out += struct.pack("<B", n)
                    out += struct.pack(f"<{n}i", *(int(v) for v in values[k + 1:k + 1 + n]))
                    k += 1 + n
                elif p[0] == b"float":
                    out += struct.pack("<f", float(values[k]))
                    k += 1
                else:
                    sys.exit(f"{src}: property type {p[0]} not handled")
    with open(dst, "wb") as f:
        f.write(out)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: ply-ascii-to-binary.py IN.ply OUT.ply")
    convert(sys.argv[1], sys.argv[2])
