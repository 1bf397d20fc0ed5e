#!/usr/bin/env python3
"""Writes bench/scenes/sky.exr, the HDR lat-long map of the hdr_fur_ball bench scene:
a blue sky graded to a pale horizon, a dark ground, and a small bright patch (a low sun
behind thin cloud, 3 degrees across, ~300x the sky) that only importance sampling of the
map finds reliably. Needs numpy only: the EXR is written uncompressed by hand.

    python3 bench/make_sky.py    # rerun only to change the map; the result is checked in
"""

import os
import struct

import numpy as np

WIDTH, HEIGHT = 256, 128
PATCH_DIR = np.array([0.5, 0.55, -0.67])  # hairtrace world space, +y up
PATCH_RADIUS_DEG = 1.5
PATCH_RADIANCE = np.array([260.0, 240.0, 210.0])


def sky():
    v = (np.arange(HEIGHT) + 0.5) / HEIGHT
    u = (np.arange(WIDTH) + 0.5) / WIDTH
    theta = np.pi * v[:, None]
    phi = 2 * np.pi * u[None, :]
    # hairtrace's lat-long orientation (src/scene/envmap.rs).
    d = np.stack([-np.sin(theta) * np.sin(phi),
                  np.cos(theta) * np.ones_like(phi),
                  np.sin(theta) * np.cos(phi)], axis=-1)
    up = d[..., 1:2]
    zenith, horizon, ground = (np.array(c) for c in
                               ([0.25, 0.4, 0.85], [0.95, 0.95, 1.0], [0.12, 0.1, 0.08]))
    t = np.clip(up, 0, 1) ** 0.5
    rgb = np.where(up > 0, horizon * (1 - t) + zenith * t, ground)
    patch = PATCH_DIR / np.linalg.norm(PATCH_DIR)
    inside = (d @ patch) > np.cos(np.radians(PATCH_RADIUS_DEG))
    return np.where(inside[..., None], PATCH_RADIANCE, rgb).astype(np.float32)


def write_exr(path, rgb):
    """A scanline float RGB OpenEXR file, uncompressed, row 0 at the top."""
    h, w, _ = rgb.shape

    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    # Channels are stored in alphabetical order: B, G, R (pixel type 2 = float).
    channels = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR")
    window = struct.pack("<4i", 0, 0, w - 1, h - 1)
    header = struct.pack("<ii", 20000630, 2) + b"".join([
        attribute("channels", "chlist", channels + b"\0"),
        attribute("compression", "compression", b"\0"),
        attribute("dataWindow", "box2i", window),
        attribute("displayWindow", "box2i", window),
        attribute("lineOrder", "lineOrder", b"\0"),
        attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        attribute("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0)),
        attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]) + b"\0"
    line = 12 * w
    start = len(header) + 8 * h
    table = struct.pack(f"<{h}Q", *(start + y * (8 + line) for y in range(h)))
    rows = b"".join(struct.pack("<ii", y, line) + rgb[y, :, ::-1].T.astype("<f4").tobytes()
                    for y in range(h))
    with open(path, "wb") as f:
        f.write(header + table + rows)


if __name__ == "__main__":
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes", "sky.exr")
    write_exr(out, sky())
    print(out)
