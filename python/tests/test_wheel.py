"""The README's Python script, in a fresh venv with the built wheel installed by pip:
at most ten lines render the demo to a numpy array and a PNG. The wheel carries its image
shim: importing the package maps no OpenImageIO, writing an image maps the shim from the
installed package."""

import os
import pathlib
import re
import subprocess
import sys


def readme_script(repo: pathlib.Path) -> str:
    text = (repo / "README.md").read_text()
    section = text[text.index("## From Python"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_script_renders_the_demo_from_a_fresh_venv(repo, tmp_path):
    script = readme_script(repo)
    assert len(script.strip().splitlines()) <= 10
    wheel = os.environ.get("HAIRTRACE_WHEEL")
    assert wheel, "scripts/python gives the wheel's path in HAIRTRACE_WHEEL"
    venv = tmp_path / "venv"
    # The venv without pip of its own: this one's pip installs into it (faster than
    # ensurepip), from PyPI or pip's cache for numpy.
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", venv], check=True)
    pip = [sys.executable, "-m", "pip", "--python", venv / "bin/python", "install", "-q",
           "--disable-pip-version-check"]
    subprocess.run([*pip, wheel], check=True)
    run = subprocess.run([venv / "bin/python", "-c", script], cwd=tmp_path, check=True,
                         capture_output=True, text=True)
    assert "(480, 640, 3) float32" in run.stdout
    assert (tmp_path / "furball.png").read_bytes().startswith(b"\x89PNG")

    # Which image shim the installed package opens, and when.
    check = (
        "import hairtrace, numpy as np\n"
        "maps = lambda: open('/proc/self/maps').read()\n"
        "print('oiio at import', 'libOpenImageIO' in maps())\n"
        "hairtrace.write_image('pixel.exr', np.ones((1, 1, 3), np.float32))\n"
        "print('shims', *sorted({l.split()[-1] for l in maps().splitlines()\n"
        "                        if 'libhairtrace-oiio' in l}))\n"
        "print('package', hairtrace.__path__[0])\n"
    )
    run = subprocess.run([venv / "bin/python", "-c", check], cwd=tmp_path, check=True,
                         capture_output=True, text=True)
    lines = dict(line.split(" ", 1) for line in run.stdout.splitlines())
    assert lines["oiio"] == "at import False", run.stdout
    package = pathlib.Path(lines["package"]).resolve()
    shims = [pathlib.Path(p) for p in lines["shims"].split()]
    assert [p.parent for p in shims] == [package], run.stdout
    assert (tmp_path / "pixel.exr").is_file()
