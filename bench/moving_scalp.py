#!/usr/bin/env python3
"""The 10^6-strand scalp swaying, as an animated USD groom: what bench/stages/scalp_1m_sway_*
read, hairtrace natively and Cycles through Blender's USD import.

    bench/.venv/bin/python bench/moving_scalp.py [OUT.usdc]

The strands are bench/stages/scalp_1m_catmull_rom_1080p.toml's (10^6 x 16 Catmull-Rom
segments, written by `hairtrace export`), at time code 1 as they are and at time code 2 swung
along +x, each point by SWAY times the square of its place along its strand (roots still), so
that a shutter open over part of the frame blurs the tips most. One time code per frame
(24 and 24), metres, +y up, widths per point (diameters), `pinned` Catmull-Rom: what hairtrace
and Blender both read as the same curves. Default OUT: target/bench-motion/scalp_1m_sway.usdc
(made on demand, never in git; its size is in docs/measurements.md, "Against Cycles'
motion blur").
"""

import importlib.util
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# bench/cycles.py is named like Blender's Cycles add-on: keep bench/ off the import path.
sys.path[:] = [p for p in sys.path
               if os.path.abspath(p or os.curdir) != os.path.join(ROOT, "bench")]

import bpy  # noqa: E402  (its Python holds the USD library)
sys.path.append(os.path.join(bpy.utils.resource_path("LOCAL"), "python", "lib",
                             f"python{sys.version_info.major}.{sys.version_info.minor}",
                             "site-packages"))
from pxr import Sdf, Usd, UsdGeom, Vt  # noqa: E402

# How far (scene units, metres) a tip swings along +x between the two time codes.
SWAY = 0.1


def read_hair(path):
    """(points per strand, points, diameters) of a .hair file as `hairtrace export` writes it,
    read by bench/cycles.py (loaded under another name: `cycles` is Blender's add-on)."""
    spec = importlib.util.spec_from_file_location(
        "peer_cycles", os.path.join(ROOT, "bench", "cycles.py"))
    peer = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(peer)
    counts, xyz, radii = peer.read_hair(path)
    return counts, xyz, 2.0 * radii


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        ROOT, "target", "bench-motion", "scalp_1m_sway.usdc")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    ht = os.path.join(ROOT, "target", "release", "hairtrace")
    scene = os.path.join(ROOT, "bench", "stages", "scalp_1m_catmull_rom_1080p.toml")
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([ht, "export", scene, "-o", tmp], check=True)
        counts, xyz, widths = read_hair(os.path.join(tmp, "groom0.hair"))
    along = np.concatenate([np.linspace(0.0, 1.0, n) for n in counts])
    swung = xyz.copy()
    swung[:, 0] += SWAY * along ** 2

    stage = Usd.Stage.CreateNew(out + ".tmp.usdc")
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(2)
    stage.SetTimeCodesPerSecond(24)
    stage.SetFramesPerSecond(24)
    root = UsdGeom.Xform.Define(stage, "/Groom")
    stage.SetDefaultPrim(root.GetPrim())
    hair = UsdGeom.BasisCurves.Define(stage, "/Groom/hair")
    hair.CreateTypeAttr(UsdGeom.Tokens.cubic)
    hair.CreateBasisAttr(UsdGeom.Tokens.catmullRom)
    hair.CreateWrapAttr(UsdGeom.Tokens.pinned)
    hair.CreateCurveVertexCountsAttr(Vt.IntArray.FromNumpy(counts.astype(np.int32)))
    hair.CreateWidthsAttr(Vt.FloatArray.FromNumpy(widths.astype(np.float32)))
    hair.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
    points = hair.CreatePointsAttr()
    points.Set(Vt.Vec3fArray.FromNumpy(xyz.astype(np.float32)), 1.0)
    points.Set(Vt.Vec3fArray.FromNumpy(swung.astype(np.float32)), 2.0)
    stage.GetRootLayer().Save()
    del stage
    # Appears only when complete.
    os.replace(out + ".tmp.usdc", out)
    print(f"{out}: {len(counts)} strands, {len(xyz)} points, 2 time samples")


if __name__ == "__main__":
    main()
