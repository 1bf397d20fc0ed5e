"""The same scene through the command line (TOML, as Rust renders it) and through Python
gives the same pixels, bit for bit."""

import subprocess

import numpy as np

import hairtrace

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
