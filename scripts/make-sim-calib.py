#!/usr/bin/env python3
"""Writes config/sim-calib.ini: the simulated rig's geometry, as a calibration file.

The simulated rig renders with exactly this calibration, so it is also the ground truth.
Rig, in the turntable frame (origin at the table centre, z up): camera 600 mm out on +x at
230 mm height, projector at the same radius and height 25 degrees around, both aimed at the
point 75 mm above the table centre; white lights as the layout argument says.
Usage: make-sim-calib.py [OUT.ini [front|ring]]
"""
import math, sys

def norm(v):
    l = math.sqrt(sum(c * c for c in v)); return [c / l for c in v]
def cross(a, b):
    return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]
def sub(a, b): return [x - y for x, y in zip(a, b)]
def matvec(m, v): return [sum(m[r][k] * v[k] for k in range(3)) for r in range(3)]
def matmul(a, b): return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]
def transpose(m): return [[m[c][r] for c in range(3)] for r in range(3)]

def look_at(eye, target):
    """World -> device rotation, rows = device x (right), y (down), z (forward)."""
    f = norm(sub(target, eye)); r = norm(cross(f, [0, 0, 1])); d = cross(f, r)
    return [r, d, f]

target = [0.0, 0.0, 75.0]
cam = [600.0, 0.0, 230.0]
a = math.radians(25.0)
proj = [600.0 * math.cos(a), 600.0 * math.sin(a), 230.0]
R_cw, R_pw = look_at(cam, target), look_at(proj, target)
R = matmul(R_pw, transpose(R_cw))
t = matvec(R_pw, sub(cam, proj))
axis_pt = matvec(R_cw, sub([0, 0, 0], cam))
axis_dir = matvec(R_cw, [0, 0, 1])
# "front" (config/sim-calib.ini): four lights high around the front half.
# "ring" (tests/eval/ring-calib.ini): eight lights around the camera, above, to the sides and
# level with the table, so that all lights on is near-uniform light on the side the camera sees
# (what the constant-illumination method assumes).
layout = sys.argv[2] if len(sys.argv) > 2 else "front"
spots = {"front": [(-70, 450, 380.0), (-30, 450, 380.0), (30, 450, 380.0), (70, 450, 380.0)],
         "ring": [(-40, 500, 420.0), (40, 500, 420.0), (-80, 450, 200.0), (80, 450, 200.0),
                  (-35, 500, 30.0), (35, 500, 30.0), (-100, 450, 30.0), (100, 450, 30.0)]}[layout]
lights = []
for deg, radius, height in spots:
    b = math.radians(deg)
    lights.append(matvec(R_cw, sub([radius * math.cos(b), radius * math.sin(b), height], cam)))

f = lambda v: ", ".join("%.9f" % x for x in v)
out = open(sys.argv[1] if len(sys.argv) > 1 else "config/sim-calib.ini", "w")
out.write("""; Calibration of the simulated rig (written by scripts/make-sim-calib.py; the simulator
; renders with exactly this geometry). Camera frame: x right, y down, z forward; millimetres.
[camera]
fx_px = 2400
fy_px = 2400
cx_px = 639.5
cy_px = 479.5
width = 1280
height = 960

[projector]
fx_px = 1900
fy_px = 1900
cx_px = 511.5
cy_px = 383.5
width = 1024
height = 768
rotation = %s
translation_mm = %s

[turntable]
axis_point_mm = %s
axis_dir = %s

[lights]
""" % (f(R[0] + R[1] + R[2]), f(t), f(axis_pt), f(axis_dir)))
for i, l in enumerate(lights):
    out.write("light_%d_mm = %s\n" % (i, f(l)))
