"""Scenes: built by keywords and numpy strands as a scene file builds them, rendered to
float32 arrays, edited without a new build where the build serves the edit, and every
bad value refused with the library's message."""

import numpy as np
import pytest

import hairtrace

SMALL = dict(width=48, height=36, spp=2)


def fur_ball_by_keywords() -> hairtrace.Scene:
    """examples/scenes/fur_ball.toml, entry for entry, through keywords."""
    s = hairtrace.Scene()
    s.set(width=480, height=360, spp=16)
    s.set_camera(eye=[1.6, 1.2, 5.6], target=[0, -0.1, 0], fov_deg=35)
    s.set_material("ginger", type="hair", melanin=np.array([0.6, 0.9]), absorption_variation=0.2,
                   roughness_variation=0.1, seed=3)
    s.set_material("skin", type="diffuse", albedo=(0.3, 0.2, 0.15))
    s.set_material("floor", type="diffuse", albedo=[0.45, 0.42, 0.4])
    s.add_groom(procedural="fur_ball", basis="bspline", shape="round", material="ginger",
                params=dict(strands=4000, segments=12, length=0.35, curl=0.4, seed=7))
    s.add_mesh(shape="sphere", radius=1.0, material="skin")
    s.add_mesh(shape="ground", y=-1.4, half_size=10, material="floor")
    s.add_light(type="environment", radiance=[0.25, 0.28, 0.32])
    s.add_light(type="distant", direction=[-0.5, 1.0, 0.8], irradiance=[3.0, 2.85, 2.6],
                angular_radius_deg=1.0)
    return s


def test_keywords_build_the_scene_file_s_scene_bit_for_bit(repo):
    file = hairtrace.Scene.load(repo / "examples/scenes/fur_ball.toml").render(**SMALL)
    keywords = fur_ball_by_keywords().render(**SMALL)
    assert file.shape == (36, 48, 3) and file.dtype == np.float32
    assert np.isfinite(file).all() and file.mean() > 0.01
    assert np.array_equal(file, keywords)


def test_aovs_and_statistics_come_with_the_image():
    image = hairtrace.Scene.demo("furball").render(aovs=["albedo", "depth", "strand"], **SMALL)
    assert isinstance(image, np.ndarray) and image.complete
    assert image.aovs["albedo"].shape == (36, 48, 3)
    assert image.aovs["depth"].shape == image.aovs["strand"].shape == (36, 48)
    assert image.stats["spp"] == 2 and image.stats["rays"] > 0
    png = image._repr_png_()
    assert png.startswith(b"\x89PNG")


def test_material_light_and_camera_edits_render_as_a_fresh_build_without_one(repo):
    # Round strands: their shapes do not depend on the view (an `auto` groom's camera edit
    # keeps the shapes its build chose, below).
    path = repo / "examples/scenes/fur_ball.toml"
    edited = hairtrace.Scene.load(path)
    edited.set(**SMALL)
    edited.render()
    edits = [
        lambda s: s.set_material("ginger", type="hair", melanin=[0.3, 0.2], beta_m=0.2),
        lambda s: s.set_lights([dict(type="distant", direction=[0, 1, 1], irradiance=[3, 3, 3])]),
        lambda s: s.add_light(type="environment", radiance=[0.2, 0.2, 0.25]),
        lambda s: s.set_camera(eye=[0, 0.5, 3], target=[0, 0, 0], fov_deg=40),
        lambda s: s.set_camera(),  # framed automatically
    ]
    for i, edit in enumerate(edits):
        edit(edited)
        fresh = hairtrace.Scene.load(path)
        fresh.set(**SMALL)
        for e in edits[: i + 1]:
            e(fresh)
        assert np.array_equal(edited.render(), fresh.render()), f"edit {i}"
        assert edited.builds == 1 and fresh.builds == 1
    # Other samples, seeds and sizes need no build (round strands hold for any view); a
    # setting the build depends on builds again, rather than being refused.
    edited.render(spp=4, seed=3, width=40)
    assert edited.builds == 1
    parts_off = edited.render(curve_parts="off")
    assert edited.builds == 2
    fresh = hairtrace.Scene.load(path)
    fresh.set(**SMALL)
    for e in edits:
        e(fresh)
    assert np.array_equal(parts_off, fresh.render(curve_parts="off"))


def test_a_groom_added_after_a_render_builds_again_as_a_fresh_scene(repo):
    path = repo / "examples/scenes/fur_ball.toml"
    scalp = dict(procedural="scalp", material="ginger", shape="round",
                 params=dict(strands=300, segments=6, seed=2))
    s = hairtrace.Scene.load(path)
    s.set(**SMALL)
    before = s.render()
    s.add_groom(**scalp)
    after = s.render()
    assert s.builds == 2 and not np.array_equal(before, after)
    fresh = hairtrace.Scene.load(path)
    fresh.add_groom(**scalp)
    assert np.array_equal(after, fresh.render(**SMALL)) and fresh.builds == 1


def test_a_farther_camera_keeps_an_auto_groom_s_build():
    s = hairtrace.Scene.demo("furball")
    s.set(**SMALL)
    s.render()
    s.set_camera(eye=[0, 1, 12], target=[0, 0, 0], fov_deg=30)
    assert np.isfinite(s.render()).all() and s.builds == 1


def test_a_closer_camera_on_auto_strands_builds_again():
    s = hairtrace.Scene.demo("furball")
    s.set(**SMALL)
    s.render()
    s.set_camera(eye=[0, 0.2, 2.2], target=[0, 0, 0], fov_deg=20)
    fresh = hairtrace.Scene.demo("furball")
    fresh.set(**SMALL)
    fresh.set_camera(eye=[0, 0.2, 2.2], target=[0, 0, 0], fov_deg=20)
    assert np.array_equal(s.render(), fresh.render())
    assert s.builds == 2


def test_numpy_strands_render():
    rng = np.random.default_rng(0)
    n, k = 300, 6
    roots = rng.uniform(-0.5, 0.5, (n, 1, 3)) * [1, 0, 1]
    points = (roots + np.linspace(0, 1, k)[None, :, None] * [0.1, 1.0, 0.0]).reshape(-1, 3)
    s = hairtrace.Scene()
    s.add_strands(points, np.full(n * k, 0.004), np.full(n, k), material="hair", basis="catmull_rom")
    s.set_material("hair", type="hair", preset="dark_brown")
    s.add_light(type="environment", radiance=[1, 1, 1])
    image = s.render(**SMALL)
    assert np.isfinite(image).all() and image.max() > 0


def test_progress_reaches_the_total_and_can_stop_the_render():
    seen = []
    image = hairtrace.Scene.demo("furball").render(progress=lambda d, t: seen.append((d, t)), **SMALL)
    assert image.complete and seen[-1][0] == seen[-1][1] == 36 * 48 * 2 or seen[-1][0] == seen[-1][1]
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)
    stopped = hairtrace.Scene.demo("furball").render(progress=lambda d, t: False, width=320, height=240, spp=64)
    assert not stopped.complete


def strands(**changes):
    base = dict(points=np.zeros((4, 3)) + [[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0]],
                radii=np.full(4, 0.01), counts=np.array([2, 2]))
    base.update(changes)
    return base


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda s: s.set(spp=0), ValueError, "spp = 0: must be >= 1"),
        (lambda s: s.set(spp="many"), ValueError, "spp = many: must be an integer"),
        (lambda s: s.set(filter_radius=float("nan")), ValueError, "filter_radius = NaN"),
        (lambda s: s.set(camera_rays=17), ValueError, "camera_rays = 17: must be [1, 16]"),
        (lambda s: s.set(sp=4), ValueError, "sp: not a render setting (the settings: width"),
        (lambda s: s.set(spp={}), TypeError, "spp: must be a number"),
        (lambda s: s.render(filter="gauss"), ValueError, "filter = gauss: must be tent | box"),
        (lambda s: s.render(aovs=["normal"]), ValueError, "\"normal\": not an AOV"),
        (lambda s: s.set_material("m", type="hair"), ValueError, "materials.m"),
        (lambda s: s.set_material("m", type="hair", melanin=[1, 0], beta_m=7), ValueError, "beta_m"),
        (lambda s: s.set_material("m", type="hair", melanin=[1, 0], model="huang", aspect=1.5), ValueError, "aspect = 1.5: must be in [0.05, 1]"),
        (lambda s: s.set_material("m", type="hair", melanin=[1, 0], model="huang", beta_m=0.3), ValueError, "beta_m"),
        (lambda s: s.add_light(type="distant", direction=[0, 1, 0], irradiance=[-1, 1, 1]), ValueError, "irradiance"),
        (lambda s: s.set_camera(eye=[0, 0, 1]), ValueError, "give both `eye` and `target`"),
        (lambda s: s.add_groom(procedural="fur_ball", material="m", params=dict(strands=-3)), ValueError, "strands"),
        (lambda s: s.add_groom(file=object()), TypeError, "file: a object cannot be"),
        (lambda s: s.add_strands(**strands(points=np.zeros((4, 2))), material="m"), ValueError, "points: shape (4, 2): must be (n, 3)"),
        (lambda s: s.add_strands(**strands(radii=np.array([0.01, -0.01, 0.01, 0.01])), material="m"), ValueError, "radius"),
        (lambda s: s.add_strands(**strands(points=np.full((4, 3), np.nan)), material="m"), ValueError, "NaN"),
        (lambda s: s.add_strands(**strands(radii=np.full(3, 0.01)), material="m"), ValueError, "radii has 3 rows and points has 4"),
        (lambda s: s.add_strands(**strands(counts=np.array([2.0, 2.0])), material="m"), TypeError, "counts: dtype float64: must be integers"),
        (lambda s: s.add_strands(**strands(counts=np.array([3, 3])), material="m"), ValueError, "strand counts add up to 6 points but 4"),
        (lambda s: s.add_strands(**strands(), file="x.hair"), TypeError, "`file` is a groom source's key"),
        (lambda s: hairtrace.Scene.load("/no/such/scene.toml"), OSError, "/no/such/scene.toml"),
        (lambda s: hairtrace.Scene.demo("cat"), ValueError, "unknown demo \"cat\""),
    ],
)
def test_bad_values_are_refused_with_the_library_s_message(call, error, message):
    s = hairtrace.Scene.demo("furball")
    with pytest.raises(error) as e:
        call(s)
    assert message in str(e.value)
    # The scene is still usable, its settings unchanged.
    assert dict(s.settings)["spp"] == "16"
