#!/usr/bin/env python3
"""Writes config/demo-rig.ini: the "true" rig of the calibration demo (make calibrate-demo).

It is config/sim-calib.ini (the nominal design) as real assembly leaves it: focal lengths 1-2%
off, principal points several pixels off, lens distortion on both camera (k1 = -0.1) and
projector, the projector a few mm and about 0.5 degrees off its design pose, the turntable axis
about 1 mm and 0.3 degrees off, each light about 10 mm off. The simulator renders with this file
([sim] rig); the firmware is only told the nominal one until `scanner calibrate` finds this.
Usage: make-demo-rig.py [NOMINAL.ini [OUT.ini]]
"""
import configparser, math, sys

def rot(axis, deg):
    """Rodrigues: rotation by deg about the unit axis."""
    l = math.sqrt(sum(a * a for a in axis)); x, y, z = (a / l for a in axis)
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg)); C = 1 - c
    return [[c + x*x*C, x*y*C - z*s, x*z*C + y*s],
            [y*x*C + z*s, c + y*y*C, y*z*C - x*s],
            [z*x*C - y*s, z*y*C + x*s, c + z*z*C]]
def matmul(a, b): return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]
def matvec(m, v): return [sum(m[r][k] * v[k] for k in range(3)) for r in range(3)]
def vec(s): return [float(x) for x in s.split(",")]
f = lambda v: ", ".join("%.9f" % x for x in v)

nominal = sys.argv[1] if len(sys.argv) > 1 else "config/sim-calib.ini"
out_path = sys.argv[2] if len(sys.argv) > 2 else "config/demo-rig.ini"
ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
ini.read(nominal)
cam, proj, tt, lights = ini["camera"], ini["projector"], ini["turntable"], ini["lights"]

R = vec(proj["rotation"]); R = [R[0:3], R[3:6], R[6:9]]
# The projector turned 0.5 degrees about a tilted axis (in its own frame: p' = dR (R p + t)) and
# shifted by (2.5, -1.5, 2) mm.
dR = rot([0.3, 1.0, 0.2], 0.5)
R2 = matmul(dR, R)
t2 = [a + b for a, b in zip(matvec(dR, vec(proj["translation_mm"])), [2.5, -1.5, 2.0])]
axis_pt = [a + b for a, b in zip(vec(tt["axis_point_mm"]), [0.8, -0.4, 0.6])]
axis_dir = matvec(rot([1.0, 0.0, 0.4], 0.3), vec(tt["axis_dir"]))
n = math.sqrt(sum(a * a for a in axis_dir)); axis_dir = [a / n for a in axis_dir]
light_offsets = [[8.0, -5.0, 6.0], [-7.0, 6.0, -5.0], [6.0, 7.0, 7.0], [-9.0, -4.0, 3.0],
                 [5.0, 8.0, -6.0], [-6.0, -7.0, 5.0], [7.0, -6.0, -7.0], [-5.0, 5.0, 8.0]]

out = open(out_path, "w")
out.write("""; The calibration demo's true rig (written by scripts/make-demo-rig.py from %s): what
; the simulator renders with under [sim] rig. Camera frame: x right, y down, z forward; mm.
[camera]
fx_px = %.6f
fy_px = %.6f
cx_px = %.6f
cy_px = %.6f
width = %s
height = %s
distortion = -0.1, 0.06, 0.0006, -0.0004, 0

[projector]
fx_px = %.6f
fy_px = %.6f
cx_px = %.6f
cy_px = %.6f
width = %s
height = %s
distortion = -0.05, 0.03, -0.0003, 0.0005, 0
rotation = %s
translation_mm = %s

[turntable]
axis_point_mm = %s
axis_dir = %s

[lights]
""" % (nominal.split("/")[-1],
       float(cam["fx_px"]) * 1.015, float(cam["fy_px"]) * 1.013, float(cam["cx_px"]) + 4.5,
       float(cam["cy_px"]) - 3.5, cam["width"], cam["height"],
       float(proj["fx_px"]) * 0.985, float(proj["fy_px"]) * 0.988, float(proj["cx_px"]) - 5.0,
       float(proj["cy_px"]) + 6.0, proj["width"], proj["height"],
       f(R2[0] + R2[1] + R2[2]), f(t2), f(axis_pt), f(axis_dir)))
for i, key in enumerate(k for k in lights):
    p = [a + b for a, b in zip(vec(lights[key]), light_offsets[i])]
    out.write("%s = %s\n" % (key, f(p)))
