"""Motion and animation from Python: strands and meshes at several time steps render bit
for bit as the C library renders the same arrays, an animated USD groom read at a frame
(with the shutter open) bit for bit as the command line's `render --frame`, and wrong
arrays are refused with errors that say what is wrong."""

import ctypes
import subprocess

import numpy as np
import pytest

import hairtrace
from c_library import f3, render

W, H = 40, 30
NAMED = dict(width=W, height=H, spp=4, seed=3, threads=2, shutter_open=-0.5, shutter_close=0.5)
SKY = [0.5, 0.5, 0.6]
EYE = [0.3, 0.2, 3.0]
HT_CURVE_LINEAR = HT_CURVE_ROUND = 0


class HtCurvesXyzr(ctypes.Structure):
    _fields_ = [("strand_count", ctypes.c_size_t), ("point_counts", ctypes.c_void_p),
                ("point_count", ctypes.c_size_t), ("points", ctypes.c_void_p),
                ("colors", ctypes.c_void_p), ("basis", ctypes.c_uint32), ("shape", ctypes.c_uint32)]


def grid(dx):
    """400 linear strands of 4 float4 control points on a 20 x 20 grid, `dx` along x."""
    s = np.arange(400)
    x = (s % 20) * 0.1 - 1.0 + dx
    z = (s // 20) * 0.1 - 1.0
    k = np.arange(4)
    points = np.zeros((400, 4, 4), np.float32)
    points[..., 0] = x[:, None] + 0.05 * k
    points[..., 1] = k * 0.4 - 0.6
    points[..., 2] = z[:, None]
    points[..., 3] = 0.01
    return points.reshape(-1, 4)


def strip(bend):
    """A strip of 8 quads along x, lifted along z by `bend` times x; and its triangles."""
    x = np.arange(9, dtype=np.float32) * 0.25 - 1.0
    positions = np.stack([np.stack([x, np.full(9, -0.5), bend * x], 1),
                          np.stack([x, np.full(9, 0.5), bend * x], 1)], 1).reshape(-1, 3)
    i = np.arange(8)
    triangles = np.stack([np.stack([2 * i, 2 * i + 2, 2 * i + 1], 1),
                          np.stack([2 * i + 1, 2 * i + 2, 2 * i + 3], 1)], 1).reshape(-1, 3)
    return positions.astype(np.float32), triangles.astype(np.uint32)


def c_render(clib, add, camera=False):
    """The scene `add(lib, scene, hair, grey)` fills through the C library, with a hair
    material (the default parameters) and a grey one, under the sky: its pixels, and the
    hair's absorption."""
    sigma_a = []

    def fill(lib, scene, ok):
        hair, grey = ctypes.c_uint32(), ctypes.c_uint32()
        params = lib.ht_hair_params_default()
        sigma_a.extend(params.sigma_a)
        ok(lib.ht_scene_add_hair_material(scene, ctypes.byref(params), ctypes.byref(hair)))
        ok(lib.ht_scene_add_diffuse_material(scene, f3([0.6, 0.5, 0.4]), ctypes.byref(grey)))
        ok(add(lib, scene, hair, grey))
        ok(lib.ht_scene_add_environment(scene, f3(SKY)))
        if camera:
            ok(lib.ht_scene_set_camera(scene, f3(EYE), f3([0, 0, 0]), f3([0, 1, 0]), ctypes.c_float(40.0)))

    return render(clib, fill, NAMED), sigma_a


def pointers(arrays):
    return (ctypes.c_void_p * len(arrays))(*[a.ctypes.data for a in arrays])


def python_scene(sigma_a):
    s = hairtrace.Scene()
    s.set_material("hair", type="hair", sigma_a=sigma_a)
    s.set_material("grey", type="diffuse", albedo=[0.6, 0.5, 0.4])
    s.add_light(type="environment", radiance=SKY)
    return s


def test_moving_strands_from_python_render_as_from_c(clib):
    steps = [grid(0.0), grid(0.05), grid(0.2)]
    counts = np.full(400, 4, np.uint32)

    def add(lib, scene, hair, grey):
        desc = HtCurvesXyzr(400, counts.ctypes.data, len(steps[0]), steps[0].ctypes.data, None,
                            HT_CURVE_LINEAR, HT_CURVE_ROUND)
        later = pointers(steps[1:])
        return lib.ht_scene_add_curves_xyzr_motion(scene, ctypes.byref(desc), later, ctypes.c_size_t(2), hair,
                                                   ctypes.byref(ctypes.c_uint32()))

    expected, sigma_a = c_render(clib, add)
    for given in (np.stack(steps), steps, [s.astype(np.float64) for s in steps]):
        s = python_scene(sigma_a)
        s.add_curves(given, counts, material="hair", basis="linear", shape="round")
        assert np.array_equal(s.render(**NAMED), expected)
    # With the shutter closed, the strands stand where it opens: another image.
    s = python_scene(sigma_a)
    s.add_curves(steps, counts, material="hair", basis="linear", shape="round")
    assert not np.array_equal(s.render(**dict(NAMED, shutter_open=0, shutter_close=0)), expected)


def test_a_deforming_mesh_from_python_renders_as_from_c(clib):
    (flat, triangles), bent = strip(0.0), strip(1.0)[0]

    def add(lib, scene, hair, grey):
        later = pointers([bent])
        return lib.ht_scene_add_mesh_motion(scene, ctypes.c_size_t(len(flat)), ctypes.c_void_p(flat.ctypes.data),
                                            later, ctypes.c_size_t(1), ctypes.c_size_t(len(triangles)),
                                            ctypes.c_void_p(triangles.ctypes.data), grey,
                                            ctypes.byref(ctypes.c_uint32()))

    expected, sigma_a = c_render(clib, add, camera=True)
    s = python_scene(sigma_a)
    s.add_triangles([flat, bent], triangles.astype(np.int64), material="grey")
    s.set_camera(eye=EYE, target=[0, 0, 0], fov_deg=40)
    assert np.array_equal(s.render(**NAMED), expected)


def swaying_by_keywords(repo, frame):
    """examples/scenes/swaying.toml made by keywords, its groom read at `frame` over the
    shutter of frames -0.5 to 6.5 from it (the time sample at 12 inside)."""
    s = hairtrace.Scene()
    s.set(width=W, height=H, spp=4, shutter_open=-0.5, shutter_close=6.5)
    s.set_material("brown", type="hair", melanin=[1.3, 0.2])
    s.set_material("floor", type="diffuse", albedo=[0.45, 0.42, 0.4])
    s.add_groom(file=repo / "examples/scenes/swaying.usda", material="brown", frame=frame)
    s.add_mesh(shape="ground", half_size=2.0, material="floor")
    s.add_light(type="environment", radiance=[0.5, 0.55, 0.6])
    s.add_light(type="distant", direction=[-0.5, 1.0, 0.8], irradiance=[3.0, 2.85, 2.6], angular_radius_deg=1.0)
    s.set_camera(eye=[0.2, 0.35, 1.4], target=[0, 0.2, 0], fov_deg=35)
    return s


def test_an_animated_groom_at_a_frame_renders_as_the_command_line(cli, repo, tmp_path):
    scene_file = repo / "examples/scenes/swaying.toml"
    size = ["--width", str(W), "--height", str(H), "--spp", "4"]

    def cli_render(*args):
        out = tmp_path / "cli.####.exr"
        subprocess.run([cli, "render", scene_file, *size, *args, "-o", out], check=True, capture_output=True)
        return hairtrace.read_image(tmp_path / "cli.0006.exr")

    still = cli_render("--frame", "6")
    assert np.array_equal(hairtrace.Scene.load(scene_file, frame=6).render(width=W, height=H, spp=4), still)
    blurred = cli_render("--frame", "6", "--set", "shutter_open=-0.5", "--set", "shutter_close=6.5")
    assert not np.array_equal(blurred, still)
    assert np.array_equal(swaying_by_keywords(repo, 6).render(), blurred)


def test_wrong_arrays_and_frames_are_refused(repo):
    s = python_scene([0.4, 0.6, 1.2])
    counts = np.full(400, 4, np.uint32)
    add = lambda points, **k: s.add_curves(points, counts, material="hair", basis="linear", **k)
    with pytest.raises(TypeError, match=r"points: dtype complex64: must be real numbers"):
        add(grid(0).astype(np.complex64))
    with pytest.raises(TypeError, match=r"points\[1\]: dtype complex64"):
        add([grid(0), grid(0).astype(np.complex64)])
    with pytest.raises(ValueError, match=r"points: shape \(1600, 3\): must be \(n, 4\) or \(K, n, 4\)"):
        add(grid(0)[:, :3])
    with pytest.raises(ValueError, match=r"points\[1\] has 1596 rows and points\[0\] has 1600"):
        add([grid(0), grid(0)[4:]])
    with pytest.raises(ValueError, match=r"130 time steps: curves in motion take 1 to 129"):
        add(np.stack([grid(0)] * 130))
    nan = grid(0.1)
    nan[7, 1] = np.nan
    with pytest.raises(ValueError, match=r"time step 1"):
        add([grid(0), nan])
    with pytest.raises(ValueError, match=r"unknown variant `cubic`"):
        s.add_curves(grid(0), counts, "hair", basis="cubic")
    flat, triangles = strip(0)
    with pytest.raises(TypeError, match=r"triangles: dtype float32: must be integers"):
        s.add_triangles(flat, triangles.astype(np.float32), material="grey")
    with pytest.raises(ValueError, match=r"positions\[1\] has 16 rows and positions\[0\] has 18"):
        s.add_triangles([flat, flat[2:]], triangles, material="grey")
    with pytest.raises(ValueError, match=r"normals on a mesh that deforms"):
        s.add_triangles([flat, flat], triangles, material="grey", normals=np.zeros_like(flat))
    with pytest.raises(TypeError, match=r"only a groom file"):
        s.add_groom(procedural="fur_ball", material="hair", frame=3)
    with pytest.raises(ValueError, match=r"frame = NaN: must be finite"):
        s.add_groom(file=repo / "examples/scenes/swaying.usda", material="hair", frame=float("nan"))
    with pytest.raises(ValueError, match=r"frame 40"):
        s.add_groom(file=repo / "examples/scenes/swaying.usda", material="hair", frame=40)
    # Nothing was added: the scene renders its sky alone.
    assert "0 grooms, 0 meshes" in repr(s)
