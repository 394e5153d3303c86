"""make eval-cycles (issue 34): a second, independent image formation for the colour eval.

Blender's Cycles renders every frame of a simulated scan again: the projector as a spot light
whose colour is the pattern image seen through the projector's lens, the white lights as point
lights, the object (the scan's truth_mesh.ply) with a Principled BSDF painted by the same
photograph the simulator wraps round it; the camera's black offset and noise added as the
simulator's camera model says. The frames are written over the scan's own (PGM/PPM), so that
`scanner process` decodes and colours what Cycles saw.

    blender -b --python-exit-code 1 -P tools/cycles_scan.py -- SCAN_DIR PATTERN_DIR IMAGE SAMPLES \
        COLOUR_SAMPLES [lambert]

SCAN_DIR: a simulated scan taken with [output] frame_format = pnm and [registration] icp = 0 (its
registration.ini poses are then the table's, exact); PATTERN_DIR: `scanner patterns` of its
config; IMAGE: the [sim] albedo_image, or uniform:A for a paint of albedo A all over (a white
reference target); SAMPLES: Cycles samples a pixel of a stripe pattern (the
decoder compares a pattern with its inverse: little noise matters), COLOUR_SAMPLES of the RGB
frames the colour is made of; lambert: a Lambertian surface lit directly only (the simulator's
own model, rendered by Cycles: what is left of the difference is the renderer's, not the
light's)."""
import configparser
import math
import os
import re
import sys

import bpy
import numpy as np
from mathutils import Matrix, Vector

BLACK_DN, READ_NOISE_DN, ELECTRONS_PER_DN = 51.0, 1.5, 20.0  # the simulator's camera defaults
PROJECTOR_DN, LIGHT_DN, REFERENCE_MM, REFERENCE_US = 170.0, 120.0, 600.0, 10000.0
PROJECTOR_BLACK, ALBEDO_MAX = 0.01, 0.9


def ini(path):
    p = configparser.ConfigParser(inline_comment_prefixes=(";",), strict=False)
    p.read(path)
    return p


def floats(text):
    return [float(x) for x in text.split(",")]


def setup_camera(cam_sec):
    w, h = int(cam_sec["width"]), int(cam_sec["height"])
    fx, cx, cy = float(cam_sec["fx_px"]), float(cam_sec["cx_px"]), float(cam_sec["cy_px"])
    data = bpy.data.cameras.new("camera")
    data.sensor_fit, data.sensor_width = "HORIZONTAL", 36.0
    data.lens = fx * 36.0 / w
    data.shift_x = (w / 2.0 - (cx + 0.5)) / w
    data.shift_y = ((cy + 0.5) - h / 2.0) / w
    data.clip_start, data.clip_end = 10.0, 100000.0
    cam = bpy.data.objects.new("camera", data)
    cam.rotation_euler = (math.pi, 0.0, 0.0)  # looks along +z, image y down: the camera frame
    bpy.context.scene.collection.objects.link(cam)
    bpy.context.scene.camera = cam
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    return w, h


def setup_projector(proj_sec):
    """A spot light at the projector's centre whose colour is its pattern image, looked up where
    each ray leaves the projector's lens (pinhole: u = fx x/z + cx). @retval the image node"""
    r = np.array(floats(proj_sec["rotation"])).reshape(3, 3)
    t = np.array(floats(proj_sec["translation_mm"]))
    w, h = int(proj_sec["width"]), int(proj_sec["height"])
    fx, fy = float(proj_sec["fx_px"]), float(proj_sec["fy_px"])
    cx, cy = float(proj_sec["cx_px"]), float(proj_sec["cy_px"])
    centre = -r.T @ t
    # the light's local axes: x the projector's x, y its -y, z its -z (a light looks along -z)
    m = Matrix(((r[0, 0], -r[1, 0], -r[2, 0], centre[0]), (r[0, 1], -r[1, 1], -r[2, 1], centre[1]),
                (r[0, 2], -r[1, 2], -r[2, 2], centre[2]), (0, 0, 0, 1)))
    data = bpy.data.lights.new("projector", "SPOT")
    data.spot_size = 2.0 * math.atan(math.hypot(w, h) / (2.0 * min(fx, fy))) + 0.1
    data.spot_blend, data.shadow_soft_size = 0.0, 0.0
    # white albedo 1 head on at the reference distance reads PROJECTOR_DN: radiance rho P /
    # (4 pi^2 d^2) of a point source of power P
    data.energy = PROJECTOR_DN / 255.0 * 4.0 * math.pi ** 2 * REFERENCE_MM ** 2
    data.use_nodes = True
    nt = data.node_tree
    nodes, links = nt.nodes, nt.links
    emission = nodes["Emission"]
    coord = nodes.new("ShaderNodeTexCoord")
    sep = nodes.new("ShaderNodeSeparateXYZ")
    links.new(coord.outputs["Normal"], sep.inputs[0])

    def math_node(op, a, b):
        n = nodes.new("ShaderNodeMath")
        n.operation = op
        for i, v in enumerate((a, b)):
            if isinstance(v, float):
                n.inputs[i].default_value = v
            else:
                links.new(v, n.inputs[i])
        return n.outputs[0]

    # local direction d: d.z < 0 ahead; projector x = d.x / -d.z, y (down) = d.y / d.z
    u = math_node("ADD", math_node("MULTIPLY", math_node("DIVIDE", sep.outputs[0], sep.outputs[2]),
                                   -fx / w), (cx + 0.5) / w)
    v = math_node("ADD", math_node("MULTIPLY", math_node("DIVIDE", sep.outputs[1], sep.outputs[2]),
                                   -fy / h), 1.0 - (cy + 0.5) / h)
    comb = nodes.new("ShaderNodeCombineXYZ")
    links.new(u, comb.inputs[0])
    links.new(v, comb.inputs[1])
    tex = nodes.new("ShaderNodeTexImage")
    tex.interpolation, tex.extension = "Closest", "CLIP"
    links.new(comb.outputs[0], tex.inputs[0])
    # the projector's black level: a black pixel still sends PROJECTOR_BLACK of white
    mix = nodes.new("ShaderNodeMixRGB")
    mix.blend_type = "MIX"
    mix.inputs[1].default_value = (PROJECTOR_BLACK,) * 3 + (1.0,)
    mix.inputs[2].default_value = (1.0, 1.0, 1.0, 1.0)
    links.new(tex.outputs["Color"], mix.inputs[0])
    links.new(mix.outputs[0], emission.inputs["Color"])
    light = bpy.data.objects.new("projector", data)
    light.matrix_world = m
    bpy.context.scene.collection.objects.link(light)
    return light, tex


def setup_lights(lights_sec, count):
    out = []
    for i in range(count):
        p = floats(lights_sec[f"light_{i}_mm"])
        data = bpy.data.lights.new(f"light {i}", "POINT")
        data.shadow_soft_size = 0.0
        data.energy = LIGHT_DN / 255.0 * 4.0 * math.pi ** 2 * REFERENCE_MM ** 2
        light = bpy.data.objects.new(f"light {i}", data)
        light.location = p
        bpy.context.scene.collection.objects.link(light)
        out.append(light)
    return out


def setup_object(scan, image, height_mm, lambert):
    bpy.ops.import_mesh.ply(filepath=f"{scan}/truth_mesh.ply")
    obj = bpy.context.selected_objects[0]
    mat = bpy.data.materials.new("photograph")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Specular"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = 1.0
    colour_input = "Base Color"
    if lambert:  # Oren-Nayar at roughness 0 is Lambert's law
        nodes.remove(bsdf)
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Roughness"].default_value = 0.0
        links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
        colour_input = "Color"
    if image.startswith("uniform:"):  # one paint all over: the white reference's target
        a = float(image.split(":", 1)[1])
        bsdf.inputs[colour_input].default_value = (a, a, a, 1.0)
        obj.data.materials.clear()
        obj.data.materials.append(mat)
        return obj
    coord = nodes.new("ShaderNodeTexCoord")
    sep = nodes.new("ShaderNodeSeparateXYZ")
    links.new(coord.outputs["Object"], sep.inputs[0])
    at = nodes.new("ShaderNodeMath")
    at.operation = "ARCTAN2"
    links.new(sep.outputs[1], at.inputs[0])  # atan2(y, x)
    links.new(sep.outputs[0], at.inputs[1])
    turn = nodes.new("ShaderNodeMath")
    turn.operation = "DIVIDE"
    links.new(at.outputs[0], turn.inputs[0])
    turn.inputs[1].default_value = 2.0 * math.pi
    wrap = nodes.new("ShaderNodeMath")
    wrap.operation = "FRACT"  # azimuth 0 .. 1 round the axis, as the simulator wraps it
    links.new(turn.outputs[0], wrap.inputs[0])
    up = nodes.new("ShaderNodeMath")
    up.operation = "DIVIDE"  # Blender's image v runs up: z over the height
    links.new(sep.outputs[2], up.inputs[0])
    up.inputs[1].default_value = height_mm
    comb = nodes.new("ShaderNodeCombineXYZ")
    links.new(wrap.outputs[0], comb.inputs[0])
    links.new(up.outputs[0], comb.inputs[1])
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = bpy.data.images.load(image)
    tex.interpolation, tex.extension = "Linear", "EXTEND"
    links.new(comb.outputs[0], tex.inputs[0])
    scale = nodes.new("ShaderNodeMixRGB")
    scale.blend_type, scale.inputs[0].default_value = "MULTIPLY", 1.0
    scale.inputs[2].default_value = (ALBEDO_MAX,) * 3 + (1.0,)
    links.new(tex.outputs["Color"], scale.inputs[1])
    links.new(scale.outputs[0], bsdf.inputs[colour_input])
    obj.data.materials.clear()
    obj.data.materials.append(mat)
    return obj


def render(path_exr):
    bpy.context.scene.render.filepath = path_exr
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path_exr)
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float32).reshape(h, w, 4)[::-1, :, :3]  # top row first
    bpy.data.images.remove(img)
    os.remove(path_exr)
    return px


def camera_dn(linear, exposure_us, rng):
    """The simulator's camera: 255 of linear radiance at the reference exposure, its black offset,
    read and shot noise, rounded and clipped."""
    signal = np.maximum(linear, 0.0) * 255.0 * exposure_us / REFERENCE_US
    sigma = np.sqrt(READ_NOISE_DN ** 2 + signal / ELECTRONS_PER_DN)
    dn = np.floor(BLACK_DN + signal + sigma * rng.standard_normal(signal.shape) + 0.5)
    return np.clip(dn, 0, 255).astype(np.uint8)


def write_pnm(path, rgb, grey):
    h, w = rgb.shape[:2]
    if grey:  # BT.601 weights; 255 where a channel clipped, as the capture marks it
        y = np.floor(0.299 * rgb[..., 0] + 0.587 * rgb[..., 1] + 0.114 * rgb[..., 2] + 0.5)
        y = np.where(np.any(rgb == 255, axis=2), 255, y).astype(np.uint8)
        data, magic = y.tobytes(), b"P5"
    else:
        data, magic = rgb.tobytes(), b"P6"
    with open(path, "wb") as f:
        f.write(magic + b"\n%d %d\n255\n" % (w, h) + data)


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    scan, patterns, image = args[0], args[1], args[2]
    samples, colour_samples = int(args[3]), int(args[4])
    lambert = len(args) > 5 and args[5] == "lambert"
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device, scene.cycles.samples = "CPU", samples
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 0 if lambert else 4  # 0: direct light only
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.view_settings.view_transform = "Standard"
    scene.display_settings.display_device = "None"  # linear radiance out
    scene.world = bpy.data.worlds.new("dark")
    scene.world.color = (0.0, 0.0, 0.0)
    calib, cfg = ini(f"{scan}/calibration.ini"), ini(f"{scan}/config.ini")
    setup_camera(calib["camera"])
    projector, pattern_tex = setup_projector(calib["projector"])
    count = int(cfg["lights"]["count"])
    lights = setup_lights(calib["lights"], count)
    obj = setup_object(scan, image, float(cfg["sim"].get("object_height_mm", "150")), lambert)
    pattern_images = {}
    rng = np.random.default_rng(7)
    views = sorted(d for d in os.listdir(scan) if re.fullmatch(r"view_\d{3}", d))
    for view in views:
        reg = ini(f"{scan}/{view}/registration.ini")["view"]
        r = np.array(floats(reg["pose_rotation"])).reshape(3, 3)
        o = np.array(floats(reg["pose_origin_mm"]))
        # p_object = R (p_camera - origin): the object in the camera frame is R^T p + origin
        m = Matrix([list(r.T[i]) + [o[i]] for i in range(3)] + [[0, 0, 0, 1]])
        obj.matrix_world = m
        capture = ini(f"{scan}/{view}/view.ini")["capture"]
        for key, what in capture.items():
            if not key.startswith("frame_"):
                continue
            index = int(key[6:])
            exposure = float(re.search(r"(\d+) us", what).group(1)) if " us" in what else \
                float(capture.get("exposure_us", REFERENCE_US))
            on = []
            if what.startswith("light "):
                on = [int(what.split()[1])]
            elif what.startswith("all lights on"):
                on = list(range(count))
            projector_on = not what.startswith(("dark", "all lights", "light "))
            for i, light in enumerate(lights):
                light.hide_render = i not in on
            projector.hide_render = not projector_on
            if projector_on:
                pattern = index  # frames 00 .. 21 are the stored patterns 0 .. 21 in order
                if pattern not in pattern_images:
                    pattern_images[pattern] = bpy.data.images.load(
                        f"{patterns}/pattern_{pattern:02d}.png")
                    pattern_images[pattern].colorspace_settings.name = "Non-Color"
                pattern_tex.image = pattern_images[pattern]
            grey = ", grey" in what
            scene.cycles.samples = samples if grey else colour_samples
            rgb = camera_dn(render(f"/tmp/cycles-{os.getpid()}.exr"), exposure, rng)
            for ext in (".pgm", ".ppm", ".pgm.zst", ".ppm.zst", ".png"):
                old = f"{scan}/{view}/frame_{index:02d}{ext}"
                if os.path.exists(old):
                    os.remove(old)
            write_pnm(f"{scan}/{view}/frame_{index:02d}{'.pgm' if grey else '.ppm'}", rgb, grey)
            print(f"cycles: {view} frame_{index:02d}: {what}", flush=True)


main()
