#!/usr/bin/env python3
"""Renders a hairtrace benchmark scene (JSON) with Blender Cycles through the `bpy` module.

    python bench/cycles.py SCENE.json --spp N --seed S --threads T --max-depth D \
        -o OUT.exr --stats STATS.json

The point is a like-for-like peer: every Cycles setting that would make it compute
something other than hairtrace's estimator (clamping, filter glossy, adaptive sampling,
denoising, guiding, the light tree, a wider pixel filter, a view transform) is turned off,
so that the two images agree to noise and their timings compare the same work. Cycles
keeps two choices of its own: Russian roulette from the first bounce on
min(1, sqrt(max throughput)), and no light sampling of a uniform environment (only
BSDF-sampled rays find it; --sample-uniform-env changes that).

- hairtrace is +y up, Blender +z up: a hairtrace point (x, y, z) is Blender (x, -z, y).
- OUT.exr is linear RGB, row 0 at the top, like hairtrace's EXR.
- STATS.json: sync_seconds and render_seconds, Cycles' own split (its render time leaves
  out scene sync, BVH build and kernel loading), read from the cycles.<layer>.*_time
  stamps Blender writes into the EXR header (0.01 s resolution); wait_seconds, the whole
  wait from reading the scene into Blender to the written image; samples (camera
  samples); closest_rays / shadow_rays from the bench/count_rays.c shim when
  HT_RAY_COUNT_FILE is set, else null.

With HT_RAY_COUNT_FILE set, the render runs in a child process: the shim writes its
counts when the process that loaded Embree exits, which must happen before this script
can put them into STATS.json.
"""

import argparse
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np

# This file is named like Blender's Cycles add-on: keep its folder off the import path, or
# bpy would load this script instead of the add-on and lose the CYCLES engine.
_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _HERE]


# ---------------------------------------------------------------------------- geometry

def to_blender(p):
    """A hairtrace point or direction in Blender's frame (+90 degrees about x)."""
    p = np.asarray(p, dtype=np.float64)
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1)


def read_hair(path):
    """Cem Yuksel's .hair file: (points per strand, points (N, 3), radii (N,)).

    Thickness in the file is a diameter; Blender wants radii."""
    data = open(path, "rb").read()
    if len(data) < 128 or data[:4] != b"HAIR":
        raise ValueError(f"{path}: not a .hair file")
    strands, points, flags, default_segments = struct.unpack_from("<4I", data, 4)
    default_thickness, = struct.unpack_from("<f", data, 20)
    offset = 128

    def take(dtype, count):
        nonlocal offset
        array = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
        offset += array.nbytes
        return array

    if flags & 1:
        counts = take("<u2", strands).astype(np.int64) + 1
    else:
        counts = np.full(strands, default_segments + 1, dtype=np.int64)
    if counts.sum() != points:
        raise ValueError(f"{path}: segment counts give {counts.sum()} points, header says {points}")
    if not flags & 2:
        raise ValueError(f"{path}: no points array")
    xyz = take("<f4", 3 * points).reshape(points, 3)
    if flags & 4:
        radii = take("<f4", points) / 2.0
    else:
        radii = np.full(points, default_thickness / 2.0, dtype=np.float32)
    # A one-point strand has no segment to trace (and Cycles asserts on it).
    keep = counts >= 2
    if not keep.all():
        per_point = np.repeat(keep, counts)
        counts, xyz, radii = counts[keep], xyz[per_point], radii[per_point]
    return counts, xyz, radii


def read_obj(path):
    """Vertices, per-corner normals and polygons (lists of vertex indices) of an OBJ file
    with `v`, `vn` and `f` lines (`a`, `a//n` or `a/t/n` corners)."""
    verts, normals, faces, corner_normals = [], [], [], []
    with open(path) as f:
        for line in f:
            fields = line.split()
            if not fields:
                continue
            if fields[0] == "v":
                verts.append([float(x) for x in fields[1:4]])
            elif fields[0] == "vn":
                normals.append([float(x) for x in fields[1:4]])
            elif fields[0] == "f":
                face, fn = [], []
                for corner in fields[1:]:
                    parts = corner.split("/")
                    v = int(parts[0])
                    face.append(v - 1 if v > 0 else len(verts) + v)
                    if len(parts) == 3 and parts[2]:
                        n = int(parts[2])
                        fn.append(n - 1 if n > 0 else len(normals) + n)
                faces.append(face)
                corner_normals.append(fn if len(fn) == len(face) else None)
    return np.array(verts, dtype=np.float64), np.array(normals, dtype=np.float64), faces, corner_normals


# ---------------------------------------------------------------------------- scene

def build_scene(scene_path, args):
    import bpy

    desc = json.load(open(scene_path))
    base = os.path.dirname(os.path.abspath(scene_path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    configure_render(scene, desc, args)
    add_camera(bpy, scene, desc)
    for i, groom in enumerate(desc.get("grooms", [])):
        add_groom(bpy, scene, i, groom, base)
    for i, mesh in enumerate(desc.get("meshes", [])):
        add_mesh(bpy, scene, i, mesh, base)
    add_lights(bpy, scene, desc.get("lights", []), base, args.sample_uniform_env)
    return scene


def configure_render(scene, desc, args):
    """Settings that make Cycles estimate what hairtrace estimates (see the module doc)."""
    render = scene.render
    render.engine = "CYCLES"
    render.resolution_x = desc["width"]
    render.resolution_y = desc["height"]
    render.resolution_percentage = 100
    render.pixel_aspect_x = render.pixel_aspect_y = 1.0
    render.threads_mode = "FIXED"
    render.threads = args.threads
    # With persistent data a second render in the same session kept the old sample count.
    render.use_persistent_data = False
    render.film_transparent = False
    render.use_compositing = False
    render.use_sequencer = False
    render.dither_intensity = 0.0
    render.use_file_extension = False
    render.filepath = os.path.abspath(args.output)
    image = render.image_settings
    image.media_type = "IMAGE"
    image.file_format = "OPEN_EXR"
    image.color_mode = "RGB"
    image.color_depth = "32"
    image.exr_codec = "ZIP"

    view = scene.view_settings
    view.view_transform = "Standard"
    view.look = "None"
    view.exposure = 0.0
    view.gamma = 1.0

    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = args.spp
    cycles.seed = args.seed
    cycles.use_animated_seed = False
    # Off unless asked for: then at the threshold given (Blender's default is 0.01), with
    # the spp as its most samples.
    cycles.use_adaptive_sampling = args.adaptive_threshold > 0
    if cycles.use_adaptive_sampling:
        cycles.adaptive_threshold = args.adaptive_threshold
    cycles.use_denoising = False
    cycles.use_light_tree = False
    cycles.use_guiding = False
    # Filter Glossy blurs sharp lobes after a blurry bounce: it would cap hair roughness.
    cycles.blur_glossy = 0.0
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    # Cycles' default (0.01): its unbiased shadow-ray roulette, the counterpart of
    # hairtrace's light_threshold, which is on by default too.
    cycles.light_sampling_threshold = 0.01
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    # Cycles counts bounces after the first hit: N bounces are N + 1 scattering events.
    bounces = max(args.max_depth - 1, 0)
    cycles.max_bounces = bounces
    cycles.diffuse_bounces = bounces
    cycles.glossy_bounces = bounces
    cycles.transmission_bounces = bounces
    cycles.transparent_max_bounces = bounces
    cycles.volume_bounces = bounces
    # A box of one pixel: each sample uniform over its own pixel, as hairtrace's box filter.
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0

    motion = desc.get("motion")
    render.use_motion_blur = motion is not None
    if motion:
        # hairtrace's shutter opens and closes at frames from the frame; Blender's is
        # centred on the (sub)frame it renders, the shutter's middle.
        open_, close = motion["shutter"]
        middle = motion["frame"] + 0.5 * (open_ + close)
        scene.frame_set(math.floor(middle), subframe=middle - math.floor(middle))
        render.motion_blur_position = "CENTER"
        render.motion_blur_shutter = close - open_
        # Blender's shutter curve is flat by default, as hairtrace's shutter: left as it is.

    curves = scene.cycles_curves
    basis = {g.get("basis", "linear") for g in desc.get("grooms", [])}
    if len(basis) > 1:
        raise ValueError("Cycles has one curve shape per scene: mixed groom bases")
    # Cycles' thick curves are Catmull-Rom; THICK_LINEAR is the linear round tube.
    curves.shape = "THICK" if basis == {"catmull-rom"} else "THICK_LINEAR"
    for g in desc.get("grooms", []):
        if g.get("shape", "round") != "round":
            raise ValueError(f"groom shape {g.get('shape')!r}: only round curves are supported")


def look_at(eye, target, up):
    """Blender's 4x4 world matrix for an object whose -Z looks from eye to target with +Y
    toward up (cameras), all in Blender coordinates."""
    forward = target - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    m = np.identity(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, true_up, -forward, eye
    return m


def add_camera(bpy, scene, desc):
    from mathutils import Matrix

    cam = desc["camera"]
    data = bpy.data.cameras.new("camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(cam["fov_y_deg"])
    data.shift_x = data.shift_y = 0.0
    # hairtrace has no near plane; Blender's smallest allowed one.
    data.clip_start = 1e-6
    data.clip_end = 1e10
    obj = bpy.data.objects.new("camera", data)
    obj.matrix_world = Matrix(look_at(to_blender(cam["eye"]), to_blender(cam["target"]),
                                      to_blender(cam["up"])).tolist())
    scene.collection.objects.link(obj)
    scene.camera = obj


def hair_material(bpy, name, m):
    """Principled Hair with our parameters: the material's model (Chiang or Huang),
    sigma_a per unit radius, roughnesses as given, no coat or randomness, and the cuticle
    tilt with Cycles' opposite sign."""
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new("ShaderNodeBsdfHairPrincipled")
    huang = m.get("model", "chiang") == "huang"
    bsdf.model = "HUANG" if huang else "CHIANG"
    bsdf.parametrization = "ABSORPTION"
    # Keyed lookup misses "Random Color" in Blender 5.0 (it only applies to melanin anyway).
    inputs = {socket.name: socket for socket in bsdf.inputs}
    inputs["Random Color"].default_value = 0.0
    inputs["Absorption Coefficient"].default_value = list(m["sigma_a"])
    inputs["IOR"].default_value = m.get("eta", 1.55)
    inputs["Offset"].default_value = -math.radians(m.get("alpha_deg", 2.0))
    inputs["Random Roughness"].default_value = 0.0
    if huang:
        inputs["Roughness"].default_value = m["roughness"]
        inputs["Aspect Ratio"].default_value = m["aspect"]
        for lobe in ("Reflection", "Transmission", "Secondary Reflection"):
            inputs[lobe].default_value = 1.0
    else:
        inputs["Roughness"].default_value = m.get("beta_m", 0.3)
        inputs["Radial Roughness"].default_value = m.get("beta_n", 0.3)
        inputs["Coat"].default_value = 0.0
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def major_axes(counts, xyz):
    """hairtrace's default orientation of an elliptical fibre at each point, in Blender's
    frame: world up made perpendicular to the strand's tangent there, or world +x where
    the tangent is vertical (`HairHit::major_axis`). The tangent at a point is the chord
    between its neighbours (one-sided at the ends)."""
    axes = np.empty_like(xyz)
    up, side = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    start = 0
    for n in counts:
        p = xyz[start:start + n]
        t = np.empty_like(p)
        t[1:-1] = p[2:] - p[:-2]
        t[0], t[-1] = p[1] - p[0], p[-1] - p[-2]
        t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-30)
        a = up - t * (t @ up)[:, None]
        flat = np.einsum("ij,ij->i", a, a) <= 1e-6
        a[flat] = side - t[flat] * (t[flat] @ side)[:, None]
        axes[start:start + n] = a / np.linalg.norm(a, axis=1, keepdims=True)
        start += n
    return axes


def groom_normals(groom, base, counts, xyz):
    """The major axis at each point in Blender's frame: the groom's own curve normals
    where the export gives them (`normals`: 3 little-endian float32 per point of the .hair
    file), else hairtrace's default orientation (`major_axes`)."""
    if "normals" not in groom:
        return major_axes(counts, to_blender(xyz))
    normals = np.fromfile(os.path.join(base, groom["normals"]), dtype="<f4").reshape(-1, 3)
    if len(normals) != len(xyz):
        raise ValueError(f"{groom['normals']}: {len(normals)} normals for {len(xyz)} points")
    return to_blender(normals)


def orient(curves, counts, axes):
    """Normal mode Free with `axes` as the normals: Cycles' Huang takes the curve normal,
    made perpendicular to the tangent, as the ellipse's major axis. (Blender 5.0.1's USD
    importer brings `custom_normal` back but not the Free mode, so an imported groom would
    be drawn with minimum-twist normals.)"""
    mode = curves.attributes.new("normal_mode", "INT8", "CURVE")
    mode.data.foreach_set("value", np.full(len(counts), 2, dtype=np.int8))
    normal = curves.attributes.new("custom_normal", "FLOAT_VECTOR", "POINT")
    normal.data.foreach_set("vector", np.asarray(axes, dtype=np.float32).ravel())


def diffuse_material(bpy, name, albedo):
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = list(albedo) + [1.0]
    bsdf.inputs["Roughness"].default_value = 0.0
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def import_usd_groom(bpy, scene, i, groom):
    """A moving groom, as Blender imports its animated USD file (its points' time samples
    through a Mesh Sequence Cache), with the groom's material; Cycles blurs the deforming
    curves. The stage's up axis and units are Blender's import's, which agree with
    hairtrace's reading of them (a Z-up stage stays Z-up; a Y-up one turns as
    `to_blender` turns hairtrace's +y up)."""
    if groom["material"].get("model") == "huang":
        # The import keeps `custom_normal` but not the Free mode (`orient`), and nothing
        # here hands it hairtrace's orientation yet: refused rather than drawn otherwise.
        raise ValueError(f"{groom['usd']}: a moving groom in the Huang model is not supported")
    before = set(bpy.data.objects)
    bpy.ops.wm.usd_import(filepath=groom["usd"], import_materials=False)
    imported = [o for o in bpy.data.objects if o not in before]
    hair = [o for o in imported if o.type == "CURVES"]
    if not hair:
        raise ValueError(f"{groom['usd']}: no curves imported")
    material = hair_material(bpy, f"hair{i}", groom["material"])
    for o in imported:
        if o.type == "CURVES":
            o.data.materials.clear()
            o.data.materials.append(material)
            o.cycles.use_motion_blur = True
            o.cycles.use_deform_motion = True
        elif o.type not in ("EMPTY",):
            bpy.data.objects.remove(o)


def add_groom(bpy, scene, i, groom, base):
    if groom.get("usd"):
        return import_usd_groom(bpy, scene, i, groom)
    counts, xyz, radii = read_hair(os.path.join(base, groom["file"]))
    curves = bpy.data.hair_curves.new(f"groom{i}")
    curves.add_curves(counts.tolist())
    curves.position_data.foreach_set("vector", to_blender(xyz).astype(np.float32).ravel())
    radius = curves.attributes.get("radius") or curves.attributes.new("radius", "FLOAT", "POINT")
    radius.data.foreach_set("value", radii.astype(np.float32))
    basis = groom.get("basis", "linear")
    if basis not in ("linear", "catmull-rom"):
        raise ValueError(f"groom basis {basis!r}: expected linear or catmull-rom")
    curves.set_types(type="POLY" if basis == "linear" else "CATMULL_ROM")
    if groom["material"].get("model") == "huang":
        orient(curves, counts, groom_normals(groom, base, counts, xyz))
    curves.materials.append(hair_material(bpy, f"hair{i}", groom["material"]))
    obj = bpy.data.objects.new(f"groom{i}", curves)
    scene.collection.objects.link(obj)


def add_mesh(bpy, scene, i, desc, base):
    verts, normals, faces, corner_normals = read_obj(os.path.join(base, desc["file"]))
    sizes = np.array([len(f) for f in faces], dtype=np.int64)
    mesh = bpy.data.meshes.new(f"mesh{i}")
    mesh.vertices.add(len(verts))
    mesh.vertices.foreach_set("co", to_blender(verts).astype(np.float32).ravel())
    mesh.loops.add(int(sizes.sum()))
    mesh.loops.foreach_set("vertex_index", np.concatenate(faces).astype(np.int32))
    mesh.polygons.add(len(faces))
    mesh.polygons.foreach_set("loop_start", (np.cumsum(sizes) - sizes).astype(np.int32))
    # With normals in the file, shade with them (smooth); without, hairtrace uses the
    # geometric normal, which is Blender's flat shading.
    smooth = len(normals) > 0 and all(n is not None for n in corner_normals)
    mesh.polygons.foreach_set("use_smooth", np.full(len(faces), smooth))
    mesh.update()
    mesh.validate()
    if smooth:
        per_corner = to_blender(normals[np.concatenate(corner_normals)])
        mesh.normals_split_custom_set(per_corner.tolist())
    mesh.materials.append(diffuse_material(bpy, f"diffuse{i}", desc["albedo"]))
    obj = bpy.data.objects.new(f"mesh{i}", mesh)
    scene.collection.objects.link(obj)


def add_lights(bpy, scene, lights, base, sample_uniform):
    """The world holds the environments (summed), suns the distant lights."""
    world = bpy.data.worlds.new("world")
    scene.world = world
    tree = world.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputWorld")
    shader = None
    for i, light in enumerate(lights):
        kind = light["type"]
        if kind in ("environment", "environment_map"):
            bg = tree.nodes.new("ShaderNodeBackground")
            if kind == "environment":
                uniform_env(bpy, tree, bg, light["radiance"], sample_uniform)
            else:
                env_map(bpy, tree, bg, light, base)
            if shader is None:
                shader = bg.outputs["Background"]
            else:
                add = tree.nodes.new("ShaderNodeAddShader")
                tree.links.new(shader, add.inputs[0])
                tree.links.new(bg.outputs["Background"], add.inputs[1])
                shader = add.outputs["Shader"]
        elif kind == "distant":
            sun(bpy, scene, i, light)
        else:
            raise ValueError(f"light type {kind!r} is not supported")
    if shader is None:
        # A new world is grey: no environment must mean black.
        bg = tree.nodes.new("ShaderNodeBackground")
        bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        shader = bg.outputs["Background"]
    tree.links.new(shader, out.inputs["Surface"])


def uniform_env(bpy, tree, bg, radiance, sample):
    """A uniform environment. Cycles never light-samples a world whose shader does not vary
    with direction (only BSDF-sampled rays reach it); hairtrace does, with MIS. `sample`
    routes the colour through a 1x1 texture, which makes Cycles sample it as hairtrace does."""
    bg.inputs["Strength"].default_value = 1.0
    if not sample:
        bg.inputs["Color"].default_value = list(radiance) + [1.0]
        return
    image = bpy.data.images.new("uniform", 1, 1, alpha=False, float_buffer=True)
    image.pixels.foreach_set(list(radiance) + [1.0])
    tex = tree.nodes.new("ShaderNodeTexEnvironment")
    tex.image = image
    tex.interpolation = "Closest"
    tree.links.new(tex.outputs["Color"], bg.inputs["Color"])


def env_map(bpy, tree, bg, light, base):
    """A lat-long map looked up exactly where hairtrace looks it up.

    In Blender's frame, hairtrace puts the map's u = 0.5 at +y and Cycles at +x, both with u
    decreasing in azimuth: turning the lookup direction by -90 degrees about +z lines them
    up. hairtrace's rotation turns the map about +y (Blender +z) counter-clockwise, so the
    lookup turns by minus that too. Rows agree already (top row = up)."""
    image = bpy.data.images.load(os.path.join(base, light["file"]), check_existing=False)
    image.alpha_mode = "NONE"
    tex = tree.nodes.new("ShaderNodeTexEnvironment")
    tex.image = image
    tex.interpolation = "Closest"
    tex.projection = "EQUIRECTANGULAR"
    coords = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "VECTOR"
    mapping.inputs["Rotation"].default_value = (
        0.0, 0.0, -math.radians(90.0 + light.get("rotation_deg", 0.0)))
    tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    tree.links.new(tex.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = light.get("scale", 1.0)


def sun(bpy, scene, i, light):
    """A sun whose disc and irradiance match hairtrace's distant light.

    Cycles' sun strength is the irradiance (W/m^2) it delivers to a surface facing it,
    whatever its angle (checked numerically: see the report), so the RGB irradiance is
    strength x colour. Its angle is the disc's full angular diameter."""
    from mathutils import Matrix

    irradiance = np.asarray(light["irradiance"], dtype=np.float64)
    strength = float(irradiance.max())
    data = bpy.data.lights.new(f"sun{i}", "SUN")
    data.energy = strength
    data.color = (irradiance / strength).tolist() if strength > 0 else [0.0, 0.0, 0.0]
    data.angle = 2.0 * math.radians(light.get("angular_radius_deg", 0.0))
    data.use_shadow = True
    obj = bpy.data.objects.new(f"sun{i}", data)
    # A sun shines along its -Z: point +Z toward the light.
    toward = to_blender(light["direction"])
    toward /= np.linalg.norm(toward)
    helper = np.array([0.0, 0.0, 1.0]) if abs(toward[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(helper, toward)
    x /= np.linalg.norm(x)
    y = np.cross(toward, x)
    m = np.identity(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = x, y, toward
    obj.matrix_world = Matrix(m.tolist())
    scene.collection.objects.link(obj)


# ---------------------------------------------------------------------------- timing

def exr_string_attributes(path):
    """The string attributes of an OpenEXR header (where Blender writes Cycles' stamps)."""
    with open(path, "rb") as f:
        data = f.read(1 << 20)
    if struct.unpack_from("<I", data, 0)[0] != 20000630:
        raise ValueError(f"{path}: not an OpenEXR file")
    pos, attributes = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        name = data[pos:name_end].decode("latin-1")
        kind = data[name_end + 1:type_end].decode("latin-1")
        size, = struct.unpack_from("<i", data, type_end + 1)
        value = data[type_end + 5:type_end + 5 + size]
        if kind == "string":
            attributes[name] = value.decode("utf-8", "replace")
        pos = type_end + 5 + size
    return attributes


def seconds(text):
    """Cycles' human-readable time ("[HH:]MM:SS.cc") in seconds."""
    parts = [float(p) for p in text.strip().split(":")]
    total = 0.0
    for p in parts:
        total = total * 60.0 + p
    return total


def render(args):
    """One render in this process; returns the timing part of the stats."""
    import bpy

    start = time.perf_counter()
    scene = build_scene(args.scene, args)
    loaded = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    wall = time.perf_counter() - loaded
    stamps = exr_string_attributes(args.output)
    found = {}
    for key, value in stamps.items():
        m = re.fullmatch(r"cycles\.(.+)\.(render_time|synchronization_time|total_time)", key)
        if m:
            found[m.group(2)] = seconds(value)
    # The whole wait: the scene read into Blender (grooms, meshes, lights), synced, built,
    # rendered and written; Python's and bpy's own start-up are left out.
    stats = {"wall_seconds": wall, "wait_seconds": loaded - start + wall,
             "blender": bpy.app.version_string,
             "uniform_env_light_sampled": args.sample_uniform_env}
    if "render_time" in found and "synchronization_time" in found:
        # Cycles' Progress: render time excludes scene update, BVH build and kernel
        # loading (added as skip time); the stamps have a resolution of 0.01 s.
        stats.update(sync_seconds=found["synchronization_time"],
                     render_seconds=found["render_time"],
                     render_seconds_source="exr stamp cycles.<layer>.render_time (0.01 s)")
    else:
        stats.update(sync_seconds=None, render_seconds=wall,
                     render_seconds_source="wall time of bpy.ops.render.render")
    return stats


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--spp", type=int, required=True)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, required=True)
    parser.add_argument("--max-depth", type=int, default=256)
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument("--stats", required=True)
    parser.add_argument("--sample-uniform-env", action="store_true",
                        help="light-sample uniform environments (with MIS) as hairtrace does; "
                             "by default Cycles reaches them by BSDF sampling only")
    parser.add_argument("--adaptive-threshold", type=float, default=0.0,
                        help="Cycles' adaptive sampling at this noise threshold (Blender's "
                             "default: 0.01); 0 (the default): off")
    # Internal: run the render here and write the timing stats to this file.
    parser.add_argument("--worker-stats", help=argparse.SUPPRESS)
    args = parser.parse_args()

    if args.worker_stats:
        json.dump(render(args), open(args.worker_stats, "w"))
        return

    desc = json.load(open(args.scene))
    count_file = os.environ.get("HT_RAY_COUNT_FILE")
    counts = None
    if count_file:
        if os.path.exists(count_file):
            os.remove(count_file)
        with tempfile.TemporaryDirectory() as tmp:
            worker = os.path.join(tmp, "timing.json")
            subprocess.run([sys.executable, os.path.abspath(__file__)] + sys.argv[1:]
                           + ["--worker-stats", worker], check=True)
            stats = json.load(open(worker))
        if os.path.exists(count_file):
            counts = json.load(open(count_file))
    else:
        stats = render(args)
    stats["samples"] = desc["width"] * desc["height"] * args.spp
    stats["closest_rays"] = counts["closest"] if counts else None
    stats["shadow_rays"] = counts["shadow"] if counts else None
    with open(args.stats, "w") as f:
        json.dump(stats, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()
