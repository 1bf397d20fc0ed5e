#!/usr/bin/env python3
"""Real grooms for the bench, made by real tools: Blender's procedural hair node assets.

    bench/.venv/bin/python bench/real_grooms.py [--out DIR] [--styles long,curly,fur]
        [--seed N] [--density F] [--preview] [--blend] [--force]

Each style is made the way an artist makes a groom in Blender 5.0 with the node groups of
`datafiles/assets/nodes/procedural_hair_node_assets.blend` (the "Hair" entries of the Add
Modifier menu), nothing placed by hand: a surface mesh (an ellipsoid head with a painted
scalp mask, or an animal body), an empty hair Curves object attached to it, and a stack
of Geometry Nodes modifiers, each one of those assets:

  Generate Hair Curves (guides: ~290 on a head, ~3900 on the body) -> combing (Displace Hair
  Curves reading a combing field painted on the surface, Trim, Shrinkwrap, Smooth) ->
  Interpolate Hair Curves (the children, at a real density) -> Clump, Curl, Frizz, Hair
  Curves Noise, Shrinkwrap -> Set Hair Curve Profile (tapered radii) -> for `long`, Set
  Curve Normal (Free: the sections' major axes from the scalp's normal).

The curves stay Blender's hair curves: Catmull-Rom, per-point `radius`. Everything is in
metres (hair radii 30-40 micrometres at the root, an ellipsoid head of semi-axes 0.078,
0.098 and 0.114 m). Each style is written to DIR/<style>/:

- `groom.usdc`: Blender's own USD exporter (`bpy.ops.wm.usd_export`) at its defaults:
  modifiers evaluated at render settings, Z-up, metersPerUnit 1; the curves (a
  BasisCurves prim) and the surface mesh. `long` also orients its strands' sections (a
  Set Curve Normal node in Free mode, the scalp's normal at each root), which the exporter
  writes as `primvars:custom_normal`.
- `head.obj`: the surface mesh alone, Blender's OBJ exporter at its defaults (Y-up, -Z
  forward: Blender's (x, y, z) is written (x, z, -y), as hairtrace turns a Z-up stage).
- `groom.blend` with `--blend`: the Blender file itself, to open and inspect (the
  modifiers live).
- `preview.png` with `--preview`: a quick Cycles render, to look at the groom.

Seeds are fixed (`--seed` shifts them all), so a run writes the same grooms every time
(the same values; the OBJ files, and most crate files, byte for byte). `--density F`
multiplies every strand density (0.1 for a quick look). Files are made on demand and
never committed (DIR defaults to target/real-grooms, which git ignores); a style whose
groom.usdc and head.obj exist is skipped unless `--force`. Prints, per style, the seconds
it took and what the written stage holds, read back with the USD library Blender ships.
"""

import argparse
import math
import os
import sys
import time

import numpy as np

# Keep bench/ off the import path: bench/cycles.py would shadow Blender's Cycles add-on.
_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _HERE]

import bpy  # noqa: E402

ROOT = os.path.dirname(_HERE)
ASSETS = os.path.join(bpy.utils.resource_path("LOCAL"), "datafiles", "assets", "nodes",
                      "procedural_hair_node_assets.blend")
STYLES = ("long", "curly", "fur")


# ---------------------------------------------------------------------------- helpers

def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.unit_settings.system = "METRIC"
    bpy.context.scene.unit_settings.scale_length = 1.0


def load_assets():
    """Appends every node group of the hair asset file (as dragging them in does)."""
    with bpy.data.libraries.load(ASSETS, link=False) as (src, dst):
        dst.node_groups = [n for n in src.node_groups if not n.startswith(".")]
    groups = {g.name: g for g in dst.node_groups}
    # Densities are per square metre here. The asset panels stop at 10000 per m^2, 1 per
    # cm^2; a real scalp has 1-2 hairs per mm^2, 1e6 to 2e6 per m^2, so the limit is
    # lifted on the appended copies, as an artist edits a group's interface.
    for name in ("Generate Hair Curves", "Interpolate Hair Curves"):
        for item in groups[name].interface.items_tree:
            if item.item_type == "SOCKET" and item.name == "Density":
                item.max_value = 1e8
    return groups


def ellipsoid(name, semi_axes, segments=96, rings=48):
    """A smooth UV sphere scaled into an ellipsoid, centred at the origin (the object's
    transform the identity), with a `UVMap`. Built from arrays rather than by
    `primitive_uv_sphere_add`, whose face order changes from run to run (and with it
    every seeded distribution on the surface)."""
    theta = np.pi * np.arange(1, rings) / rings  # from the top pole down
    phi = 2.0 * np.pi * np.arange(segments) / segments
    ring = np.stack([np.outer(np.sin(theta), np.cos(phi)), np.outer(np.sin(theta), np.sin(phi)),
                     np.repeat(np.cos(theta)[:, None], segments, axis=1)], axis=-1)
    verts = np.concatenate([[[0.0, 0.0, 1.0]], ring.reshape(-1, 3), [[0.0, 0.0, -1.0]]])
    verts *= np.asarray(semi_axes)
    top, bottom = 0, len(verts) - 1

    def at(i, j):  # ring i (0 = nearest the top), segment j
        return 1 + i * segments + j % segments

    faces, uvs = [], []
    for j in range(segments):
        u0, u1 = j / segments, (j + 1) / segments
        faces.append((top, at(0, j), at(0, j + 1)))
        uvs.append(((u0 + u1) / 2, 1.0, u0, 1 - 1 / rings, u1, 1 - 1 / rings))
    for i in range(rings - 2):
        v0, v1 = 1 - (i + 1) / rings, 1 - (i + 2) / rings
        for j in range(segments):
            u0, u1 = j / segments, (j + 1) / segments
            faces.append((at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)))
            uvs.append((u0, v0, u0, v1, u1, v1, u1, v0))
    for j in range(segments):
        u0, u1 = j / segments, (j + 1) / segments
        faces.append((at(rings - 2, j), bottom, at(rings - 2, j + 1)))
        uvs.append((u0, 1 / rings, (u0 + u1) / 2, 0.0, u1, 1 / rings))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts.tolist(), [], faces)
    uv = mesh.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", np.concatenate(uvs).astype(np.float32))
    mesh.shade_smooth()
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def vertices(mesh):
    co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def smoothstep(a, b, x):
    t = np.clip((x - a) / (b - a), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def paint(obj, name, weights):
    """A vertex group (what weight painting makes): the density mask of the hair."""
    group = obj.vertex_groups.new(name=name)
    for level in np.unique(np.round(weights, 3)):
        if level <= 0.0:
            continue
        idx = np.nonzero(np.round(weights, 3) == level)[0].tolist()
        group.add(idx, float(level), "REPLACE")


def comb(obj, name, vectors):
    """A vector attribute on the surface's vertices (what an artist paints or builds to
    comb guides): Generate Hair Curves carries it to each curve's root, and Displace Hair
    Curves reads its Displace Vector from it."""
    attr = obj.data.attributes.new(name, "FLOAT_VECTOR", "POINT")
    attr.data.foreach_set("vector", np.asarray(vectors, dtype=np.float32).ravel())


def hair_object(name, surface):
    """An empty hair Curves object attached to `surface` (Add > Curves > Empty Hair)."""
    curves = bpy.data.hair_curves.new(name)
    curves.surface = surface
    curves.surface_uv_map = surface.data.uv_layers.active.name
    obj = bpy.data.objects.new(name, curves)
    obj.matrix_world = surface.matrix_world.copy()
    bpy.context.scene.collection.objects.link(obj)
    return obj


def modifier(obj, groups, group, **inputs):
    """Adds one asset as a Geometry Nodes modifier and sets its inputs by their panel names
    (spaces as underscores). `Surface` is the surface object; a value `("attr", name)`
    reads a field input from the named attribute (e.g. a vertex group)."""
    ng = groups[group]
    mod = obj.modifiers.new(group, "NODES")
    mod.node_group = ng
    sockets = {}
    for item in ng.interface.items_tree:
        if item.item_type == "SOCKET" and item.in_out == "INPUT":
            key = item.name.replace(" ", "_")
            if item.socket_type == "NodeSocketObject":
                key += "_object"
            sockets.setdefault(key, item)
    for key, value in inputs.items():
        if key == "Surface":
            key = "Surface_object"
        if key not in sockets:
            raise KeyError(f"{group}: no input {key!r}; it has {sorted(sockets)}")
        ident = sockets[key].identifier
        if isinstance(value, tuple) and len(value) == 2 and value[0] == "attr":
            mod[ident + "_use_attribute"] = True
            mod[ident + "_attribute_name"] = value[1]
        else:
            mod[ident] = value
    return mod


def surface_normals(obj, attribute="surface_normal"):
    """Orients the strands' elliptical sections: a Geometry Nodes modifier with a Set Curve
    Normal node in Free mode whose normal is the named attribute, `surface_normal` (the
    surface's normal at each root, which Generate and Interpolate Hair Curves leave on the
    curves). Blender stores the result as `custom_normal`, which its USD exporter writes as
    `primvars:custom_normal`; a renderer takes it, made perpendicular to the strand, as the
    major axis (docs/conventions.md, section 4b)."""
    tree = bpy.data.node_groups.new("Hair Normals from Surface", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    source, sink = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    named = nodes.new("GeometryNodeInputNamedAttribute")
    named.data_type = "FLOAT_VECTOR"
    named.inputs["Name"].default_value = attribute
    normal = nodes.new("GeometryNodeSetCurveNormal")
    normal.inputs["Mode"].default_value = "Free"
    links.new(source.outputs["Geometry"], normal.inputs["Curve"])
    links.new(named.outputs["Attribute"], normal.inputs["Normal"])
    links.new(normal.outputs["Curve"], sink.inputs["Geometry"])
    obj.modifiers.new("Hair Normals from Surface", "NODES").node_group = tree


def hair_material(name, melanin):
    """Principled Hair by melanin: for the preview and the .blend (the bench scenes give
    their own materials)."""
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new("ShaderNodeBsdfHairPrincipled")
    bsdf.model = "CHIANG"
    bsdf.parametrization = "MELANIN"
    inputs = {s.name: s for s in bsdf.inputs}
    inputs["Melanin"].default_value = melanin
    inputs["Melanin Redness"].default_value = 0.1
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def skin_material(name, albedo):
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = list(albedo) + [1.0]
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


# ---------------------------------------------------------------------------- heads

HEAD_AXES = (0.078, 0.098, 0.114)  # half breadth, half length (face at -y), half height


def head(scalp_front, scalp_back):
    """An ellipsoid head, face toward -y, with a `scalp` vertex group: hair above a line
    that runs from the forehead (normalised height `scalp_front`) down to the nape
    (`scalp_back`), and not over the ears."""
    obj = ellipsoid("head", HEAD_AXES)
    n = vertices(obj.data) / np.asarray(HEAD_AXES)
    back = (n[:, 1] + 1.0) / 2.0  # 0 at the face, 1 at the back
    line = scalp_front + (scalp_back - scalp_front) * smoothstep(0.0, 1.0, back)
    ears = np.exp(-(((np.abs(n[:, 0]) - 1.0) / 0.25) ** 2 + ((n[:, 1] - 0.05) / 0.25) ** 2
                    + ((n[:, 2] + 0.05) / 0.3) ** 2))
    weights = smoothstep(line, line + 0.15, n[:, 2]) * (1.0 - ears)
    paint(obj, "scalp", np.clip(weights, 0.0, 1.0))
    obj.data.materials.append(skin_material("skin", (0.63, 0.45, 0.38)))
    return obj


# ---------------------------------------------------------------------------- styles

def head_comb(surface, down, side, back, back_front):
    """The combing field of a head: down by `down`, away from a centre parting by `side`,
    back by `back`, and back by `back_front` more at the forehead, so that the hair there
    is swept back over the scalp rather than over the face."""
    n = vertices(surface.data) / np.asarray(HEAD_AXES)
    front = smoothstep(-0.1, -0.7, n[:, 1])
    v = np.stack([side * np.tanh(n[:, 0] / 0.2) * (1.0 - 0.5 * front),
                  back + back_front * front,
                  -down * np.ones(len(n))], axis=1)
    comb(surface, "comb", v)


def style_long(groups, seed, density):
    """Long, straight-ish brown hair: 30-point strands about 0.3 m long, parted in the
    middle, combed down over the head and the back, in soft clumps, tapered."""
    surface = head(scalp_front=0.45, scalp_back=-0.55)
    head_comb(surface, down=1.2, side=0.06, back=0.05, back_front=1.0)
    hair = hair_object("long", surface)
    hair.data.materials.append(hair_material("hair_brown", 0.6))
    # Guides: ~290 on the scalp, 30 points, growing out along the normal.
    modifier(hair, groups, "Generate Hair Curves", Surface=surface, Hair_Length=0.20,
             Control_Points=30, Density=5000.0, Density_Mask=("attr", "scalp"),
             Seed=seed, Hair_Material=hair.data.materials[0])
    # Comb the guides (the `comb` field), push them out of the head onto the scalp, cut
    # them to length (from the root) and smooth the kinks.
    modifier(hair, groups, "Displace Hair Curves", Displace_Vector=("attr", "comb"),
             Shape=0.5)
    modifier(hair, groups, "Trim Hair Curves", Replace_Length=True, Length=0.45)
    modifier(hair, groups, "Shrinkwrap Hair Curves", Surface=surface, Offset_Distance=0.008,
             Above_Surface=0.0, Smoothing_Steps=3)
    modifier(hair, groups, "Trim Hair Curves", Replace_Length=True, Length=0.32,
             Random_Offset=0.06, Seed=seed + 1)
    modifier(hair, groups, "Smooth Hair Curves", Amount=0.5, Iterations=5, Shape=0.0,
             Preserve_Length=True)
    modifier(hair, groups, "Shrinkwrap Hair Curves", Surface=surface, Offset_Distance=0.006,
             Above_Surface=0.0, Smoothing_Steps=2)
    # Children: 1 per mm^2 on the scalp.
    modifier(hair, groups, "Interpolate Hair Curves", Surface=surface,
             Interpolation_Guides=4, Density=1.0e6 * density,
             Density_Mask=("attr", "scalp"), Seed=seed + 2)
    modifier(hair, groups, "Clump Hair Curves", Factor=0.5, Shape=0.6, Tip_Spread=0.004,
             Guide_Distance=0.012, Seed=seed + 3, Preserve_Length=True)
    modifier(hair, groups, "Hair Curves Noise", Distance=0.006, Shape=0.6, Scale=20.0,
             Scale_along_Curve=2.0, Offset_per_Curve=0.3, Seed=seed + 4, Preserve_Length=True)
    modifier(hair, groups, "Frizz Hair Curves", Factor=0.3, Distance=0.002, Shape=0.8,
             Seed=seed + 5, Preserve_Length=True)
    # Children that cut through the head between their guides are pushed out of it.
    modifier(hair, groups, "Shrinkwrap Hair Curves", Surface=surface, Offset_Distance=0.002,
             Above_Surface=0.0, Smoothing_Steps=0)
    modifier(hair, groups, "Set Hair Curve Profile", Radius=40e-6, Shape=0.15,
             Factor_Min=0.3, Factor_Max=1.0)
    # Each (elliptical) section stands with its major axis along the scalp's normal at the root.
    surface_normals(hair)
    return surface, hair


def style_curly(groups, seed, density):
    """Curly dark hair: 0.22 m strands combed down with volume, gathered in clumps that
    curl together as ringlets, frizzy at the ends."""
    surface = head(scalp_front=0.4, scalp_back=-0.5)
    head_comb(surface, down=0.8, side=0.15, back=0.05, back_front=0.6)
    hair = hair_object("curly", surface)
    hair.data.materials.append(hair_material("hair_dark", 0.9))
    modifier(hair, groups, "Generate Hair Curves", Surface=surface, Hair_Length=0.15,
             Control_Points=16, Density=5000.0, Density_Mask=("attr", "scalp"),
             Seed=seed, Hair_Material=hair.data.materials[0])
    modifier(hair, groups, "Displace Hair Curves", Displace_Vector=("attr", "comb"),
             Shape=0.5)
    modifier(hair, groups, "Trim Hair Curves", Replace_Length=True, Length=0.3)
    modifier(hair, groups, "Shrinkwrap Hair Curves", Surface=surface, Offset_Distance=0.02,
             Above_Surface=0.0, Smoothing_Steps=3)
    modifier(hair, groups, "Trim Hair Curves", Replace_Length=True, Length=0.22,
             Random_Offset=0.05, Seed=seed + 1)
    modifier(hair, groups, "Smooth Hair Curves", Amount=0.5, Iterations=5, Shape=0.0,
             Preserve_Length=True)
    modifier(hair, groups, "Shrinkwrap Hair Curves", Surface=surface, Offset_Distance=0.015,
             Above_Surface=0.0, Smoothing_Steps=2)
    modifier(hair, groups, "Interpolate Hair Curves", Surface=surface,
             Interpolation_Guides=3, Density=6.0e5 * density,
             Density_Mask=("attr", "scalp"), Seed=seed + 2)
    modifier(hair, groups, "Clump Hair Curves", Factor=0.7, Shape=0.3, Tip_Spread=0.002,
             Guide_Distance=0.01, Seed=seed + 3, Preserve_Length=True)
    modifier(hair, groups, "Curl Hair Curves", Subdivision=2, Curl_Start=0.08, Radius=0.007,
             Factor_Start=0.5, Factor_End=1.0, Frequency=12.0, Random_Offset=0.15,
             Seed=seed + 4, Guide_Distance=0.01)
    modifier(hair, groups, "Frizz Hair Curves", Factor=0.5, Distance=0.002, Shape=0.7,
             Seed=seed + 5, Preserve_Length=False)
    modifier(hair, groups, "Shrinkwrap Hair Curves", Surface=surface, Offset_Distance=0.002,
             Above_Surface=0.0, Smoothing_Steps=0)
    modifier(hair, groups, "Set Hair Curve Profile", Radius=35e-6, Shape=0.2,
             Factor_Min=0.35, Factor_Max=1.0)
    return surface, hair


def style_fur(groups, seed, density):
    """Short dense fur on an elongated animal body: 2 cm strands combed toward the tail
    (+x) and down, slightly clumped, thin at the tips."""
    body = ellipsoid("body", (0.22, 0.09, 0.10), segments=128, rings=64)
    n = vertices(body.data) / np.asarray((0.22, 0.09, 0.10))
    # Thinner on the belly, full on the back and flanks.
    paint(body, "fur", 0.45 + 0.55 * smoothstep(-0.9, -0.2, n[:, 2]))
    body.data.materials.append(skin_material("skin", (0.5, 0.42, 0.36)))
    hair = hair_object("fur", body)
    hair.data.materials.append(hair_material("fur_blonde", 0.25))
    modifier(hair, groups, "Generate Hair Curves", Surface=body, Hair_Length=0.022,
             Control_Points=8, Density=20000.0, Density_Mask=("attr", "fur"), Seed=seed,
             Hair_Material=hair.data.materials[0])
    modifier(hair, groups, "Displace Hair Curves", Displace_Vector=(0.02, 0.0, -0.008),
             Shape=0.4)
    modifier(hair, groups, "Shrinkwrap Hair Curves", Surface=body, Offset_Distance=0.004,
             Above_Surface=0.0, Smoothing_Steps=2)
    modifier(hair, groups, "Trim Hair Curves", Replace_Length=True, Length=0.022,
             Random_Offset=0.008, Seed=seed + 1)
    modifier(hair, groups, "Interpolate Hair Curves", Surface=body, Interpolation_Guides=4,
             Density=1.5e6 * density, Density_Mask=("attr", "fur"), Seed=seed + 2)
    modifier(hair, groups, "Clump Hair Curves", Factor=0.35, Shape=0.7, Tip_Spread=0.0005,
             Guide_Distance=0.004, Seed=seed + 3, Preserve_Length=True)
    modifier(hair, groups, "Hair Curves Noise", Distance=0.0015, Shape=0.6, Scale=80.0,
             Scale_along_Curve=1.0, Offset_per_Curve=0.5, Seed=seed + 4, Preserve_Length=True)
    modifier(hair, groups, "Set Hair Curve Profile", Radius=30e-6, Shape=0.6,
             Factor_Min=0.2, Factor_Max=1.0)
    return body, hair


BUILDERS = {"long": style_long, "curly": style_curly, "fur": style_fur}


# ---------------------------------------------------------------------------- export

def export(surface, hair, folder, blend):
    os.makedirs(folder, exist_ok=True)
    usd = os.path.join(folder, "groom.usdc")
    obj = os.path.join(folder, "head.obj")
    # Operators (the exporters, saving, loading the next scene) first bring the viewport's
    # depsgraph up to date: with the hair hidden in the viewport its modifiers run once,
    # in the USD exporter's own render-time evaluation (hide_viewport is not render
    # visibility). It stays hidden there.
    hair.hide_viewport = True
    # Blender's USD exporter at its defaults: render-time evaluation of the modifiers, no
    # axis conversion (Z-up), metres.
    bpy.ops.wm.usd_export(filepath=usd, evaluation_mode="RENDER")
    bpy.ops.object.select_all(action="DESELECT")
    surface.select_set(True)
    bpy.context.view_layer.objects.active = surface
    # The OBJ exporter at its defaults: Y up, -Z forward; the surface alone.
    bpy.ops.wm.obj_export(filepath=obj, export_selected_objects=True)
    if blend:
        # Saved with the hair visible, which evaluates it once more.
        hair.hide_viewport = False
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(folder, "groom.blend"),
                                    check_existing=False)
        hair.hide_viewport = True
    return usd, obj


def usd_stats(path):
    """What the written stage holds, read back with the USD library Blender ships."""
    sys.path.append(os.path.join(bpy.utils.resource_path("LOCAL"), "python", "lib",
                                 f"python{sys.version_info.major}.{sys.version_info.minor}",
                                 "site-packages"))
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(path)
    stats = {"upAxis": UsdGeom.GetStageUpAxis(stage),
             "metersPerUnit": UsdGeom.GetStageMetersPerUnit(stage), "curves": []}
    for prim in stage.Traverse():
        if not prim.IsA(UsdGeom.BasisCurves):
            continue
        c = UsdGeom.BasisCurves(prim)
        counts = np.asarray(c.GetCurveVertexCountsAttr().Get())
        widths = np.asarray(c.GetWidthsAttr().Get())
        points = np.asarray(c.GetPointsAttr().Get())
        xf = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
        stats["curves"].append({
            "prim": str(prim.GetPath()),
            "type": c.GetTypeAttr().Get(), "basis": c.GetBasisAttr().Get(),
            "wrap": c.GetWrapAttr().Get(),
            "widths_interpolation": c.GetWidthsInterpolation(),
            "curves": len(counts), "points": int(counts.sum()),
            "points_per_curve": (int(counts.min()), int(counts.max())),
            "width_range": (float(widths.min()), float(widths.max())),
            "bounds": (points.min(axis=0).tolist(), points.max(axis=0).tolist()),
            "identity": xf == xf.GetIdentity() if hasattr(xf, "GetIdentity") else None,
            "transform": [list(r) for r in xf],
            # The names a renderer reads curve normals from (hairtrace: all three).
            "normals": [name for name in ("normals", "primvars:normals", "primvars:custom_normal")
                        if prim.HasAttribute(name) and prim.GetAttribute(name).HasAuthoredValue()],
            "primvars": sorted(p.GetPrimvarName() for p in
                               UsdGeom.PrimvarsAPI(prim).GetPrimvarsWithAuthoredValues()),
        })
    return stats


def preview(folder, hair):
    """A quick Cycles look at the groom from the front right, lit by a grey sky and a
    sun: `preview.png` (480x480, 16 spp)."""
    from mathutils import Vector

    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 16
    scene.cycles.device = "CPU"
    scene.render.resolution_x = scene.render.resolution_y = 480
    scene.render.filepath = os.path.join(folder, "preview.png")
    scene.render.image_settings.file_format = "PNG"
    world = bpy.data.worlds.new("world")
    scene.world = world
    background = world.node_tree.nodes.new("ShaderNodeBackground")
    background.inputs["Color"].default_value = (0.5, 0.55, 0.6, 1.0)
    output = world.node_tree.nodes.new("ShaderNodeOutputWorld")
    world.node_tree.links.new(background.outputs["Background"], output.inputs["Surface"])
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(40.0), 0.0, math.radians(30.0))
    scene.collection.objects.link(sun)
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    hair.hide_viewport = False
    evaluated = hair.evaluated_get(bpy.context.evaluated_depsgraph_get())
    corners = [hair.matrix_world @ Vector(c) for c in evaluated.bound_box]
    centre = sum(corners, Vector()) / 8.0
    radius = max((c - centre).length for c in corners)
    direction = Vector((0.5, -1.0, 0.2)).normalized()
    cam.data.angle = math.radians(30.0)
    cam.location = centre + direction * radius / math.sin(math.radians(15.0))
    cam.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
    bpy.ops.render.render(write_still=True)
    hair.hide_viewport = True


# ---------------------------------------------------------------------------- main

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=os.path.join(ROOT, "target", "real-grooms"))
    parser.add_argument("--styles", default=",".join(STYLES),
                        help=f"comma-separated, of: {', '.join(STYLES)}")
    parser.add_argument("--seed", type=int, default=0, help="shifts every seed")
    parser.add_argument("--density", type=float, default=1.0,
                        help="factor on every strand density (0.1: a quick look)")
    parser.add_argument("--force", action="store_true", help="rewrite existing grooms")
    parser.add_argument("--preview", action="store_true", help="also render preview.png")
    parser.add_argument("--blend", action="store_true",
                        help="also save groom.blend (the scene, modifiers live)")
    args = parser.parse_args()
    styles = [s for s in args.styles.split(",") if s]
    for s in styles:
        if s not in BUILDERS:
            parser.error(f"unknown style {s!r}; expected some of {', '.join(STYLES)}")
    for style in styles:
        folder = os.path.join(args.out, style)
        usd = os.path.join(folder, "groom.usdc")
        obj = os.path.join(folder, "head.obj")
        if os.path.exists(usd) and os.path.exists(obj) and not args.force:
            print(f"{style}: {folder} has its groom.usdc and head.obj (--force to rewrite)",
                  flush=True)
            continue
        start = time.perf_counter()
        reset()
        groups = load_assets()
        surface, hair = BUILDERS[style](groups, 1000 * args.seed + 17 * (1 + STYLES.index(style)),
                                        args.density)
        usd, obj = export(surface, hair, folder, args.blend)
        seconds = time.perf_counter() - start
        stats = usd_stats(usd)
        print(f"{style}: {seconds:.1f} s; up {stats['upAxis']}, metersPerUnit "
              f"{stats['metersPerUnit']:g}; groom.usdc {os.path.getsize(usd) / 1e6:.1f} MB, "
              f"head.obj {os.path.getsize(obj) / 1e6:.2f} MB", flush=True)
        for c in stats["curves"]:
            lo, hi = c["points_per_curve"]
            print(f"  {c['prim']}: {c['curves']} curves, {c['points']} points "
                  f"({lo}-{hi} per curve), {c['type']} {c['basis']} {c['wrap']}, widths "
                  f"{c['widths_interpolation']} {c['width_range'][0] * 1e6:.1f}-"
                  f"{c['width_range'][1] * 1e6:.1f} um, normals "
                  f"{', '.join(c['normals']) or 'none'}, primvars {c['primvars']}, bounds "
                  + " .. ".join("(" + ", ".join(f"{v:.3f}" for v in b) + ")"
                                for b in c["bounds"]), flush=True)
        if args.preview:
            preview(folder, hair)


if __name__ == "__main__":
    main()
