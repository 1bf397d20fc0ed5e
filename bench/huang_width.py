#!/usr/bin/env python3
"""How much of an elliptical fibre Cycles' Huang hair leaves out: measured in Cycles alone.

    bench/.venv/bin/python bench/huang_width.py coverage SCENE_DIR... [--spp N] [--threads T]
    bench/.venv/bin/python bench/huang_width.py predict ROUND_DIR OVAL_DIR [--spp N]
    bench/.venv/bin/python bench/huang_width.py sheet [--spp N] [--threads T]

Cycles' Principled Hair in its Huang mode draws the fibre as the round tube of the curve's
radius, but a hit whose offset |h| across the tube lies outside the ellipse's projected
half-width (sqrt(1 - (1 - aspect^2) x^2 / (x^2 + z^2)), (x, z) the direction toward the
ray's origin in the section's frame, x along the major axis) gets a transparent closure
instead of the hair's (`bsdf_hair_huang_setup` in Cycles' kernel/closure/
bsdf_principled_hair_huang.h): those rays go on through. hairtrace's fibre covers the
tube's width (docs/conventions.md, section 4b).

- `coverage`: renders each peer scene (a `peer/scene.json` that `hairtrace export` wrote,
  under SCENE_DIR, as bench/peer leaves it in target/bench-peer/NAME/) with Cycles as
  bench/cycles.py sets it up, but a transparent film and one bounce, and prints the mean
  alpha: the share of camera rays that end on hair rather than passing through to the
  background. Writes SCENE_DIR/alpha.npy (rows from the top).
- `predict`: from two scenes that differ only in the aspect (bench/peer's huang_fur_ball,
  huang_oval_fur_ball, with their references and `coverage` run on both): hairtrace's
  fibre covers what Cycles' round fibre covers (alpha of ROUND), Cycles' elliptical one
  only its alpha. With the hair's radiance L at a pixel taken as hairtrace's (its
  reference H = alpha_round L + (1 - alpha_round) sky), Cycles' image is predicted as
  H + (alpha_round - alpha_oval)(sky - L): the camera rays' share of the difference alone.
  Prints the means and RMSEs of H, the prediction and Cycles' reference.
- `sheet`: parallel strands (radius r, 4r apart) over a plane, the sections' major axes
  vertical, a sun straight above: the coverage seen from above (camera rays), and the
  light that passes between the strands onto a translucent plane seen from below (shadow
  rays), for aspect 1 and 0.65, against the geometry's 2r / 4r and 2 aspect r / 4r.
"""

import argparse
import importlib.util
import json
import math
import os
import sys
import tempfile

import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
# Keep bench/ off the import path (bench/cycles.py would shadow Blender's Cycles add-on);
# load it under another name for its scene set-up.
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _HERE]
_spec = importlib.util.spec_from_file_location("peer_cycles", os.path.join(_HERE, "cycles.py"))
peer = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(peer)

import bpy  # noqa: E402


def read_exr(path):
    """RGBA of an EXR, rows from the top (as hairtrace and bench/cycles.py write them)."""
    image = bpy.data.images.load(path, check_existing=False)
    w, h = image.size
    pixels = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(h, w, 4)[::-1]


def render_rgba(scene, path):
    scene.render.filepath = path
    scene.render.image_settings.color_mode = "RGBA"
    bpy.ops.render.render(write_still=True)
    return read_exr(path)


def coverage(scene_dir, spp, threads):
    """Mean alpha of the peer scene under SCENE_DIR, in Cycles with a transparent film."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "alpha.exr")
        args = argparse.Namespace(spp=spp, seed=7, threads=threads, max_depth=1, output=out,
                                  sample_uniform_env=False, adaptive_threshold=0.0)
        scene = peer.build_scene(os.path.join(scene_dir, "peer", "scene.json"), args)
        scene.render.film_transparent = True
        # Alpha needs no light paths, only the transparent bounces through the fibres.
        scene.cycles.transparent_max_bounces = 256
        alpha = render_rgba(scene, out)[..., 3]
    np.save(os.path.join(scene_dir, "alpha.npy"), alpha)
    return alpha


def predict(round_dir, oval_dir):
    """Cycles' oval image predicted from hairtrace's and the two coverages (module doc)."""
    a1 = np.load(os.path.join(round_dir, "alpha.npy"))[..., None]
    a2 = np.load(os.path.join(oval_dir, "alpha.npy"))[..., None]
    h = read_exr(os.path.join(oval_dir, "reference-hairtrace.exr"))[..., :3]
    c = read_exr(os.path.join(oval_dir, "reference-Cycles.exr"))[..., :3]
    lights = json.load(open(os.path.join(oval_dir, "peer", "scene.json")))["lights"]
    if [light["type"] for light in lights] != ["environment"]:
        sys.exit(f"{oval_dir}: the prediction needs a uniform sky as the only light")
    sky = np.asarray(lights[0]["radiance"], dtype=np.float32)
    hair = a1 > 1e-3
    radiance = np.where(hair, (h - (1 - a1) * sky) / np.where(hair, a1, 1), sky)
    p = h + (a1 - a2) * (sky - radiance)

    def rmse(x, y):
        return float(np.sqrt(np.mean((x - y) ** 2)))

    print(f"alpha: round {a1.mean():.4f}, oval {a2.mean():.4f} "
          f"(camera rays through the oval fibres: {a1.mean() - a2.mean():.4f} of the image)")
    print(f"means: hairtrace {h.mean():.4f}, predicted Cycles {p.mean():.4f}, "
          f"Cycles {c.mean():.4f}")
    print(f"RMSE against Cycles' reference: hairtrace {rmse(h, c):.4f}, "
          f"predicted {rmse(p, c):.4f}")


# ---------------------------------------------------------------------------- the sheet

SHEET = dict(radius=0.005, spacing=0.02, length=2.0, height=0.05, view=0.4, size=64)


def sheet_scene(aspect, spp, threads, below):
    """Strands along x at z = height over a plane at z = 0, major axes along +z, a sun
    straight above; a camera looking down at the strands (film transparent) or up at
    the plane's underside (translucent: it shows the light that reaches its top)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    s = SHEET
    desc = {"width": s["size"], "height": s["size"], "grooms": [{"basis": "linear"}]}
    args = argparse.Namespace(spp=spp, seed=3, threads=threads, max_depth=1, output="",
                              sample_uniform_env=False, adaptive_threshold=0.0)
    peer.configure_render(scene, desc, args)
    n = int(s["length"] / s["spacing"])
    y = (np.arange(n) - (n - 1) / 2) * s["spacing"]
    xyz = np.zeros((n, 2, 3))
    xyz[:, 0, 0], xyz[:, 1, 0] = -s["length"] / 2, s["length"] / 2
    xyz[:, :, 1], xyz[:, :, 2] = y[:, None], s["height"]
    curves = bpy.data.hair_curves.new("sheet")
    curves.add_curves([2] * n)
    curves.position_data.foreach_set("vector", xyz.astype(np.float32).ravel())
    radius = curves.attributes.get("radius") or curves.attributes.new("radius", "FLOAT", "POINT")
    radius.data.foreach_set("value", np.full(2 * n, s["radius"], dtype=np.float32))
    curves.set_types(type="POLY")
    peer.orient(curves, [2] * n, np.tile([0.0, 0.0, 1.0], (2 * n, 1)))
    # Black hair: nothing passes through a fibre, only between (or beside) them.
    curves.materials.append(peer.hair_material(bpy, "hair", {
        "sigma_a": [200.0] * 3, "model": "huang", "roughness": 0.3, "aspect": aspect}))
    scene.collection.objects.link(bpy.data.objects.new("sheet", curves))
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy, sun.data.angle = 1.0, 0.0
    scene.collection.objects.link(sun)
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", s["view"]
    scene.collection.objects.link(cam)
    scene.camera = cam
    if below:
        bpy.ops.mesh.primitive_plane_add(size=s["length"])
        plane = bpy.context.active_object
        mat = bpy.data.materials.new("translucent")
        tree = mat.node_tree
        tree.nodes.clear()
        out = tree.nodes.new("ShaderNodeOutputMaterial")
        tree.links.new(tree.nodes.new("ShaderNodeBsdfTranslucent").outputs["BSDF"],
                       out.inputs["Surface"])
        plane.data.materials.append(mat)
        cam.location, cam.rotation_euler = (0.0, 0.0, -3.0), (math.pi, 0.0, 0.0)
    else:
        cam.location = (0.0, 0.0, 3.0)
        scene.render.film_transparent = True
        scene.cycles.transparent_max_bounces = 256
    return scene


def sheet(spp, threads):
    s = SHEET
    full = 2 * s["radius"] / s["spacing"]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "sheet.exr")
        bare = None
        for aspect in (1.0, 0.65):
            seen = render_rgba(sheet_scene(aspect, spp, threads, below=False), out)[..., 3].mean()
            lit = render_rgba(sheet_scene(aspect, spp, threads, below=True), out)[..., :3].mean()
            if bare is None:
                scene = sheet_scene(aspect, spp, threads, below=True)
                bpy.data.objects.remove(bpy.data.objects["sheet"])
                bare = render_rgba(scene, out)[..., :3].mean()
            print(f"aspect {aspect}: camera rays end on hair {seen:.4f} of the view (tube "
                  f"{full:.4f}, ellipse edge-on {aspect * full:.4f}); light reaching the "
                  f"plane {lit / bare:.4f} (tube {1 - full:.4f}, ellipse "
                  f"{1 - aspect * full:.4f})", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("what", choices=("coverage", "predict", "sheet"))
    parser.add_argument("dirs", nargs="*")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    if args.what == "coverage":
        for d in args.dirs:
            alpha = coverage(d, args.spp, args.threads)
            print(f"{d}: mean alpha {alpha.mean():.5f} ({args.spp} spp)", flush=True)
    elif args.what == "predict":
        predict(*args.dirs)
    else:
        sheet(args.spp, args.threads)


if __name__ == "__main__":
    main()
