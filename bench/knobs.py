#!/usr/bin/env python3
"""What the hair fidelity knobs (deep_bounce_depth, lobe_cull) and the shadow-ray
roulette's light_threshold cost and buy on the bench scenes, measured with the CLI: for
each scene, a reference of the exact settings at 8x the scene's spp (a seed no timed render uses), then REPEATS rounds in which every
variant renders the scene as written at its spp (seed = round), the variants
interleaved so that a load change on a shared machine touches them alike. Prints a
Markdown table of medians: path-tracing seconds, the process's CPU time relative to the
exact settings', rays per camera sample, RMSE against
the reference (its own noise taken out, as the report does) and efficiency
1 / (RMSE^2 x CPU seconds) relative to the exact settings; and each knob's bias: the RMSE
between its own render at the reference's spp and seed and the reference (the shared
seed makes their noise largely common, so this is mostly the knob's converged error,
an upper bound of it), and the change of the image's mean it brings (energy gained or
lost; the pixels' noise averages out of it).

    cargo build --release && python3 bench/knobs.py [--repeats 3] [--scenes a,b] [--threads 2]
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# HT_HAIRTRACE: another build of the CLI (one that later builds do not replace mid-run).
HAIRTRACE = Path(os.environ.get("HT_HAIRTRACE", ROOT / "target" / "release" / "hairtrace"))
SCENES = ["fur_ball", "demo_fur_ball", "hdr_fur_ball", "scalp", "white_fur_ball"]
VARIANTS = {
    "exact": [],
    "deep_bounce_depth 1": ["--deep-bounce-depth", "1"],
    "deep_bounce_depth 2": ["--deep-bounce-depth", "2"],
    "deep_bounce_depth 4": ["--deep-bounce-depth", "4"],
    "deep_bounce_depth 8": ["--deep-bounce-depth", "8"],
    "deep_bounce_depth 16": ["--deep-bounce-depth", "16"],
    "lobe_cull 0.01": ["--lobe-cull", "0.01"],
    "lobe_cull 0.1": ["--lobe-cull", "0.1"],
    # The shadow-ray roulette around its default (0.03): unbiased, so only speed and noise.
    "light_threshold 0": ["--light-threshold", "0"],
    "light_threshold 0.01": ["--light-threshold", "0.01"],
    "light_threshold 0.1": ["--light-threshold", "0.1"],
}
REFERENCE_SEED = "1000003"


def spp_of(scene: Path) -> int:
    for line in scene.read_text().splitlines():
        if line.replace(" ", "").startswith("spp="):
            return int(line.split("=")[1].split("#")[0])
    return 16


def render(scene, out, spp, seed, threads, extra):
    """Path-tracing seconds, rays per camera sample and the CPU seconds of the whole
    process (build included: less disturbed by other work on a shared machine)."""
    stats = out.with_suffix(".json")
    cmd = [str(HAIRTRACE), "render", str(scene), "--spp", str(spp), "--seed", str(seed),
           "--threads", str(threads), "-o", str(out), "--stats", str(stats), *extra]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    s = json.loads(stats.read_text())
    return s["seconds"], s["rays"] / max(s["samples"], 1), cpu


def compare(image, reference):
    """`hairtrace compare --json`: rmse, mean, reference_mean, max_abs."""
    o = subprocess.run([str(HAIRTRACE), "compare", str(image), str(reference), "--json"],
                       check=True, capture_output=True, text=True)
    return json.loads(o.stdout)


def rmse(image, reference):
    return compare(image, reference)["rmse"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--no-bias", action="store_true", help="skip the bias renders")
    ap.add_argument("--variants", help="comma-separated names (exact is always run)")
    args = ap.parse_args()
    if args.variants:
        wanted = {"exact", *args.variants.split(",")}
        for v in [v for v in VARIANTS if v not in wanted]:
            del VARIANTS[v]
    tmp = Path(tempfile.mkdtemp(prefix="knobs-"))
    print("| scene | variant | seconds | CPU time vs exact | rays/sample | RMSE "
          "| efficiency vs exact (CPU time) | bias (RMSE at 8x spp, shared seed) | image mean change |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in args.scenes.split(","):
        scene = ROOT / "bench" / "scenes" / f"{name}.toml"
        spp = spp_of(scene)
        reference = tmp / f"{name}_ref.exr"
        render(scene, reference, 8 * spp, REFERENCE_SEED, args.threads, [])
        bias = {"exact": (0.0, 0.0)}
        for v, extra in [] if args.no_bias else list(VARIANTS.items())[1:]:
            out = tmp / f"{name}_{v.replace(' ', '_')}_bias.exr"
            render(scene, out, 8 * spp, REFERENCE_SEED, args.threads, extra)
            c = compare(out, reference)
            bias[v] = (c["rmse"], c["mean"] / c["reference_mean"] - 1)
        names = list(VARIANTS)
        runs = {v: [] for v in VARIANTS}
        for seed in range(1, args.repeats + 1):
            # Each round starts one variant later, so that none always runs first.
            k = (seed - 1) % len(VARIANTS)
            for v in names[k:] + names[:k]:
                out = tmp / f"{name}_{v.replace(' ', '_')}_{seed}.exr"
                seconds, rays, cpu = render(scene, out, spp, seed, args.threads, VARIANTS[v])
                runs[v].append((seconds, rays, rmse(out, reference), cpu))
        # The reference carries the exact settings' variance / 8: taken out of every MSE.
        exact_mse = statistics.median(r[2] ** 2 for r in runs["exact"])
        noise = exact_mse * (1 / 8) / (1 + 1 / 8)
        rows = {}
        for v, r in runs.items():
            seconds = statistics.median(x[0] for x in r)
            rays = statistics.median(x[1] for x in r)
            err = max(statistics.median(x[2] ** 2 for x in r) - noise, 0.0) ** 0.5
            cpu = statistics.median(x[3] for x in r)
            rows[v] = (seconds, rays, err, cpu)
        # Efficiency on CPU time: on a shared machine it moves far less than wall time.
        base = 1 / (rows["exact"][2] ** 2 * rows["exact"][3])
        for v, (seconds, rays, err, cpu) in rows.items():
            eff = 1 / (err ** 2 * cpu) / base if err > 0 else float("inf")
            b = f"{bias[v][0]:.3g} | {100 * bias[v][1]:+.2f}%" if v in bias else " | "
            print(f"| {name} | {v} | {seconds:.3f} | {cpu / rows['exact'][3]:.3f} | {rays:.2f} "
                  f"| {err:.4g} | {eff:.3f} | {b} |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
