"""Blender 3.4 (Debian's, in background mode) imports a scan's mesh.ply, mesh.obj, mesh.stl and mesh.glb
with its own importers and their default settings, in a scene whose unit is the millimetre
(how a user working with scans sets it): each must come in upright (the turntable's axis along
Blender's Z) at the object's true size, and the three must agree; with a texture, mesh.obj's and
mesh.glb's materials take their base colour from it.

    blender -b --python-exit-code 1 -P tests/blender_import.py -- SCAN_DIR HEIGHT_MM"""
import os
import sys

import bpy
import numpy

# Blender 3.4's glTF importer still says numpy.bool, which numpy 1.24 (Debian 12's) removed: the
# importer fails with "module 'numpy' has no attribute 'bool'". The alias it meant is bool.
if not hasattr(numpy, "bool"):
    numpy.bool = bool


def texture_size(obj):
    """The size of the image the object's first material takes its base colour from (None)."""
    for node in obj.data.materials[0].node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            for link in node.inputs["Base Color"].links:
                if link.from_node.type == "TEX_IMAGE" and link.from_node.image is not None:
                    return tuple(link.from_node.image.size)
    return None


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    scan, height = args[0], float(args[1])
    bpy.ops.wm.read_factory_settings(use_empty=True)
    units = bpy.context.scene.unit_settings
    units.system, units.length_unit, units.scale_length = "METRIC", "MILLIMETERS", 0.001
    importers = {
        "mesh.ply": lambda p: bpy.ops.import_mesh.ply(filepath=p),
        "mesh.obj": lambda p: bpy.ops.wm.obj_import(filepath=p),  # its defaults: Y up, -Z forward
        "mesh.stl": lambda p: bpy.ops.import_mesh.stl(filepath=p),
        "mesh.glb": lambda p: bpy.ops.import_scene.gltf(filepath=p),  # metres, +Y up
    }
    sizes = {}
    textured = None  # the texture's size when the scan has one (texture.png beside mesh.obj)
    if os.path.exists(f"{scan}/texture.png"):
        img = bpy.data.images.load(f"{scan}/texture.png")
        textured = tuple(img.size)
        bpy.data.images.remove(img)
    for name, load in importers.items():
        before = set(bpy.data.objects)
        load(f"{scan}/{name}")
        (obj,) = set(bpy.data.objects) - before
        if name == "mesh.glb":  # glTF's materials (one per cluster with fit) too
            assert len(obj.data.materials) >= 1, name
        if name in ("mesh.obj", "mesh.glb") and textured:  # the texture, found and read
            size = texture_size(obj)
            assert size == textured, (name, "texture", size, textured)
            print(f"blender: {name}: its material's base colour is the {size[0]} x {size[1]} texture")
        elif name == "mesh.glb":  # else its vertex colours
            assert len(obj.data.color_attributes) == 1, name
        pts = [obj.matrix_world @ v.co for v in obj.data.vertices]
        lo = [min(p[k] for p in pts) for k in range(3)]
        hi = [max(p[k] for p in pts) for k in range(3)]
        size = [hi[k] - lo[k] for k in range(3)]
        sizes[name] = (size, lo, hi)
        print(f"blender: {name}: {len(obj.data.vertices)} vertices, {size[0]:.1f} x {size[1]:.1f} x "
              f"{size[2]:.1f} mm, from z {lo[2]:.1f} to {hi[2]:.1f}")
        # upright: standing on the table (z from about 0) to the object's height along Z
        assert abs(size[2] - height) < 0.05 * height, (name, "height", size)
        assert -5.0 < lo[2] < 5.0, (name, "not on the table", lo)
    ref = sizes["mesh.ply"]
    for name, (size, lo, hi) in sizes.items():
        for k in range(3):
            assert abs(lo[k] - ref[1][k]) < 0.01 and abs(hi[k] - ref[2][k]) < 0.01, \
                (name, "differs from mesh.ply", lo, hi, ref)
    print("blender: mesh.ply, mesh.obj, mesh.stl and mesh.glb upright, %.1f mm tall, the same in all"
          % ref[0][2])


main()
