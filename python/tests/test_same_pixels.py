"""The same scene through the command line (TOML, as Rust renders it), through the C
library and through Python gives the same pixels, bit for bit."""

import ctypes
import subprocess

import numpy as np

import hairtrace
from c_library import f3, render

SETTINGS = ["--width", "64", "--height", "48", "--spp", "4"]


def cli_render(cli, tmp_path, *args):
    out = tmp_path / "cli.exr"
    subprocess.run([cli, "render", *args, *SETTINGS, "-o", out], check=True, capture_output=True)
    return hairtrace.read_image(out)


def test_the_demo_renders_the_same_through_the_command_line_and_python(cli, tmp_path):
    expected = cli_render(cli, tmp_path, "--demo", "furball")
    image = hairtrace.Scene.demo("furball").render(width=64, height=48, spp=4)
    assert expected.shape == image.shape == (48, 64, 3)
    assert np.array_equal(expected, image)


def test_a_scene_file_renders_the_same_through_the_command_line_and_python(cli, tmp_path, repo):
    path = repo / "examples/scenes/scalp.toml"
    expected = cli_render(cli, tmp_path, path)
    image = hairtrace.Scene.load(path).render(width=64, height=48, spp=4)
    assert np.array_equal(expected, image)


class HtCurves(ctypes.Structure):
    _fields_ = [("strand_count", ctypes.c_size_t), ("point_counts", ctypes.c_void_p),
                ("point_count", ctypes.c_size_t), ("points", ctypes.c_void_p),
                ("radii", ctypes.c_void_p), ("radius", ctypes.c_float),
                ("colors", ctypes.c_void_p), ("basis", ctypes.c_uint32), ("shape", ctypes.c_uint32)]


HT_CURVE_BSPLINE = HT_CURVE_AUTO = 2
W, H = 40, 30
NAMED = dict(width=W, height=H, spp=4, seed=11, threads=2, max_depth=8)
EYE, SKY, SUN_DIR, SUN = [0.3, 0.4, 4.0], [0.3, 0.35, 0.4], [1.0, 1.0, 1.0], [2.0, 2.0, 1.8]


def strands():
    """A small tuft of `auto` B-spline strands, in float32 as both hosts take them."""
    rng = np.random.default_rng(4)
    n, k = 200, 6
    roots = rng.uniform(-0.6, 0.6, (n, 1, 3)).astype(np.float32)
    t = np.linspace(0, 1, k, dtype=np.float32)[None, :, None]
    points = (roots + t * np.array([0.2, 1.0, 0.1], np.float32)).reshape(-1, 3)
    radii = np.full(n * k, 0.006, np.float32)
    return points, radii, np.full(n, k, np.uint32)


def c_render(clib):
    sigma_a = []

    def fill(lib, scene, ok):
        material = ctypes.c_uint32()
        params = lib.ht_hair_params_default()
        sigma_a.extend(params.sigma_a)
        ok(lib.ht_scene_add_hair_material(scene, ctypes.byref(params), ctypes.byref(material)))
        points, radii, counts = strands()
        curves = HtCurves(len(counts), counts.ctypes.data, len(radii), points.ctypes.data, radii.ctypes.data,
                          0.0, None, HT_CURVE_BSPLINE, HT_CURVE_AUTO)
        ok(lib.ht_scene_add_curves(scene, ctypes.byref(curves), material, ctypes.byref(ctypes.c_uint32())))
        ok(lib.ht_scene_add_environment(scene, f3(SKY)))
        ok(lib.ht_scene_add_distant_light(scene, f3(SUN_DIR), f3(SUN), ctypes.c_float(0.0)))
        ok(lib.ht_scene_set_camera(scene, f3(EYE), f3([0, 0, 0]), f3([0, 1, 0]), ctypes.c_float(40.0)))

    return render(clib, fill, NAMED), sigma_a


def test_the_same_scene_renders_the_same_through_c_and_python(clib):
    expected, sigma_a = c_render(clib)
    assert expected.mean() > 0
    s = hairtrace.Scene()
    s.set_material("hair", type="hair", sigma_a=sigma_a)
    points, radii, counts = strands()
    s.add_strands(points, radii, counts, material="hair", basis="bspline", shape="auto")
    s.add_light(type="environment", radiance=SKY)
    s.add_light(type="distant", direction=SUN_DIR, irradiance=SUN)
    s.set_camera(eye=EYE, target=[0, 0, 0], fov_deg=40)
    assert np.array_equal(s.render(**NAMED), expected)
