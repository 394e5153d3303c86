#!/usr/bin/python3
"""What the VM's display showed (qemu screendumps, tests/gpio_chip.sh) against the pattern
drm-show put up: the Gray-code sequence of a 1024 x 768 projector, columns only. Prints one line
per screendump: its size and how many pixels differ from the pattern."""
import glob
import os
import sys

WIDTH, HEIGHT, BITS = 1024, 768, 10


def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:  # P6, width, height, maxval, with comments skipped
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P6":
        raise ValueError("not a binary PPM")
    return int(fields[1]), int(fields[2]), data[pos + 1:]


def lit(pattern, x):
    if pattern == 0:
        return True
    if pattern == 1:
        return False
    k, inverse = (pattern - 2) // 2, (pattern - 2) % 2
    gray = x ^ (x >> 1)
    return bool((gray >> (BITS - 1 - k)) & 1) != bool(inverse)


def main(work):
    shots = sorted(glob.glob(os.path.join(work, "shot-*.ppm")))
    if not shots:
        print("no screendumps")
        return 1
    for path in shots:
        what, number = os.path.basename(path)[5:-4].split("-")
        width, height, pixels = read_ppm(path)
        expect_row = [what == "pattern" and lit(int(number), x) for x in range(width)]
        differ = 0
        for y in range(height):
            row = pixels[3 * width * y:3 * width * (y + 1)]
            for x in range(width):
                r, g, b = row[3 * x], row[3 * x + 1], row[3 * x + 2]
                on = r >= 250 and g >= 250 and b >= 250
                off = r <= 5 and g <= 5 and b <= 5
                differ += not (on if expect_row[x] else off)
        print(f"{what} {number}: {width}x{height}, {differ} pixels differ")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
