#!/usr/bin/env python3
"""hairtrace against Blender Cycles on the bench scenes, on this machine, in one run.

    bench/peer [--quick] [--scenes fur_ball,scalp] [--repeats 3] [--threads 2]

(bench/peer sets up the virtual environment, builds hairtrace and the ray-counting shim,
then runs this file.) For each scene of bench/scenes/:

1. `hairtrace export` writes the scene for Cycles (bench/cycles.py reads it).
2. A reference: each renderer renders it at `REFERENCE_FACTOR` x the scene's spp with a
   seed no timed render uses (a render sharing the reference's seed shares its first
   samples and its RMSE comes out too low). The reference is the mean of the two, so
   neither renderer is measured against its own bias; the distance between the two
   (converged difference) is reported against the noise the two references carry.
3. Timed renders at the scene's spp, hairtrace and Cycles interleaved, `--repeats` times
   with different seeds: path-tracing seconds (scene build or sync excluded), camera
   samples per second, rays per camera sample, RMSE against the reference, efficiency
   1 / (RMSE^2 x seconds). Medians are reported. Cycles renders twice, with its adaptive
   sampling off and on at Blender's default threshold (`CYCLES_ADAPTIVE`, the spp then
   its most samples); hairtrace is compared with the better of the two on each scene, and
   the table says which. hairtrace renders with the scene's own settings (its
   `allocation` among them); `--allocation` renders it once more with that allocation.

RMSE against the mean of two references needs no pixel arithmetic here: for images x, a,
b, |x - (a + b)/2|^2 = |x - a|^2 / 2 + |x - b|^2 / 2 - |a - b|^2 / 4 per pixel, so the
mean squared errors against a, b and between a and b (from `hairtrace compare`) give it
exactly.
"""

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HAIRTRACE = os.path.join(ROOT, "target", "release", "hairtrace")
CYCLES = os.path.join(ROOT, "bench", "cycles.py")
SCENES = os.path.join(ROOT, "bench", "scenes")
REFERENCE_SEED = 1_000_003
REFERENCE_FACTOR = 16
# Blender's default noise threshold for Cycles' adaptive sampling.
CYCLES_ADAPTIVE = 0.01


def run(cmd, env=None):
    result = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if result.returncode != 0:
        sys.exit(f"bench: {' '.join(cmd)} failed:\n{result.stderr.strip()}")
    return result.stdout


def mse(image, reference):
    out = run([HAIRTRACE, "compare", image, reference, "--json"])
    c = json.loads(out)
    return c["rmse"] ** 2, c["mean"], c["reference_mean"]


class Scene:
    def __init__(self, name, work, args):
        self.name = name
        self.path = os.path.join(SCENES, name + ".toml")
        with open(self.path, "rb") as f:
            render = tomllib.load(f).get("render", {})
        self.spp = max(1, render.get("spp", 16) // (4 if args.quick else 1))
        self.max_depth = render.get("max_depth", 256)
        self.width, self.height = render.get("width", 640), render.get("height", 480)
        self.work = os.path.join(work, name)
        self.threads = args.threads
        self.shim = args.shim
        os.makedirs(self.work, exist_ok=True)
        run([HAIRTRACE, "export", self.path, "-o", os.path.join(self.work, "peer")])

    def hairtrace(self, spp, seed, out, allocation=None):
        stats = out + ".json"
        extra = ["--allocation", allocation] if allocation else []
        run([HAIRTRACE, "render", self.path, "--spp", str(spp), "--seed", str(seed),
             "--threads", str(self.threads), "--max-depth", str(self.max_depth),
             "--filter", "box", "-o", out, "--stats", stats] + extra)
        with open(stats) as f:
            s = json.load(f)
        return {"seconds": s["seconds"], "samples": s["samples"], "rays": s["rays"]}

    def cycles(self, spp, seed, out, adaptive=0.0):
        stats = out + ".json"
        env = dict(os.environ)
        if self.shim:
            env["LD_PRELOAD"] = self.shim
            env["HT_RAY_COUNT_FILE"] = out + ".rays.json"
        run([sys.executable, CYCLES, os.path.join(self.work, "peer", "scene.json"),
             "--spp", str(spp), "--seed", str(seed), "--threads", str(self.threads),
             "--max-depth", str(self.max_depth), "--adaptive-threshold", str(adaptive),
             "-o", out, "--stats", stats], env=env)
        with open(stats) as f:
            s = json.load(f)
        rays = None
        if s.get("closest_rays") is not None:
            rays = s["closest_rays"] + (s.get("shadow_rays") or 0)
        return {"seconds": s["render_seconds"], "samples": s["samples"], "rays": rays}


def measure(scene, repeats, allocation, log):
    references = {"hairtrace": scene.hairtrace, "Cycles": scene.cycles}
    renderers = dict(references)
    if allocation:
        renderers[f"hairtrace allocation {allocation}"] = (
            lambda spp, seed, out: scene.hairtrace(spp, seed, out, allocation))
    renderers["Cycles adaptive"] = (
        lambda spp, seed, out: scene.cycles(spp, seed, out, CYCLES_ADAPTIVE))
    ref = {}
    ref_spp = scene.spp * REFERENCE_FACTOR
    for name, render in references.items():
        ref[name] = os.path.join(scene.work, f"reference-{name}.exr")
        t = time.time()
        render(ref_spp, REFERENCE_SEED, ref[name])
        log(f"  {name} reference, {ref_spp} spp: {time.time() - t:.0f} s wall")
    ref_mse_ab, mean_h, mean_c = mse(ref["hairtrace"], ref["Cycles"])
    runs = {name: [] for name in renderers}
    for seed in range(1, repeats + 1):
        for name, render in renderers.items():
            out = os.path.join(scene.work, f"{name.replace(' ', '-')}-{seed}.exr")
            r = render(scene.spp, seed, out)
            ea, mean, _ = mse(out, ref["hairtrace"])
            eb, _, _ = mse(out, ref["Cycles"])
            r["rmse"] = math.sqrt(max(0.0, (ea + eb) / 2 - ref_mse_ab / 4))
            r["mean"] = mean
            runs[name].append(r)
            log(f"  {name} seed {seed}: {r['seconds']:.3f} s, RMSE {r['rmse']:.5f}")
    rows = {}
    for name, rs in runs.items():
        seconds = statistics.median(r["seconds"] for r in rs)
        rmse = statistics.median(r["rmse"] for r in rs)
        rays = [r["rays"] / r["samples"] for r in rs if r["rays"] is not None]
        rows[name] = {
            "seconds": seconds,
            "samples_per_second": rs[0]["samples"] / seconds,
            "rays_per_sample": statistics.median(rays) if rays else None,
            "rmse": rmse,
            "efficiency": 1.0 / (rmse * rmse * seconds),
            "runs": rs,
        }
    # Each reference carries the noise of a timed render divided by REFERENCE_FACTOR in
    # variance; the two differ by both.
    expected = math.sqrt(sum(rows[n]["rmse"] ** 2 for n in references) / REFERENCE_FACTOR)
    best = max(("Cycles", "Cycles adaptive"), key=lambda n: rows[n]["efficiency"])
    converged = {
        "rmse_between_references": math.sqrt(ref_mse_ab),
        "expected_from_noise": expected,
        "mean_hairtrace": mean_h,
        "mean_cycles": mean_c,
    }
    return {"scene": scene.name, "spp": scene.spp, "reference_spp": ref_spp,
            "size": [scene.width, scene.height], "max_depth": scene.max_depth,
            "threads": scene.threads, "renderers": rows, "converged": converged,
            "best_cycles": best}


def table(results):
    lines = [
        "| scene | renderer | path tracing s | camera samples/s | rays/sample | RMSE "
        "| efficiency 1/(RMSE²·s) | vs Cycles' better |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for res in results:
        # Against Cycles' better setting on this scene, adaptive sampling off or on.
        cycles = res["renderers"][res["best_cycles"]]["efficiency"]
        w, h = res["size"]
        label = f"{res['scene']} ({w}x{h}, {res['spp']} spp)"
        for name, r in res["renderers"].items():
            rays = "n/a" if r["rays_per_sample"] is None else f"{r['rays_per_sample']:.2f}"
            lines.append(
                f"| {label} | {name} | {r['seconds']:.2f} | {r['samples_per_second'] / 1e6:.3f} M "
                f"| {rays} | {r['rmse']:.5f} | {r['efficiency']:.0f} "
                f"| {r['efficiency'] / cycles:.2f}x |")
    lines.append("")
    lines.append("| scene | converged difference (RMSE between references) | expected from their noise "
                 "| mean hairtrace | mean Cycles |")
    lines.append("|---|---|---|---|---|")
    for res in results:
        c = res["converged"]
        lines.append(
            f"| {res['scene']} ({res['reference_spp']} spp each) | {c['rmse_between_references']:.5f} "
            f"| {c['expected_from_noise']:.5f} | {c['mean_hairtrace']:.5f} | {c['mean_cycles']:.5f} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", help="comma-separated names from bench/scenes/ (default: all)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--quick", action="store_true", help="a quarter of each scene's spp")
    parser.add_argument("--work", default=os.path.join(ROOT, "target", "bench-peer"))
    parser.add_argument("--shim", help="the ray-counting LD_PRELOAD library for Cycles")
    parser.add_argument("--json", help="also write the results here")
    parser.add_argument("--allocation", choices=["uniform", "noise"],
                        help="also render hairtrace with this allocation")
    args = parser.parse_args()
    names = (args.scenes.split(",") if args.scenes else
             sorted(f[:-5] for f in os.listdir(SCENES) if f.endswith(".toml")))

    def log(message):
        print(message, file=sys.stderr, flush=True)

    results = []
    for name in names:
        log(f"{name}:")
        results.append(measure(Scene(name, args.work, args), args.repeats, args.allocation, log))
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), platform.processor())
    print(f"Machine: {cpu}, {os.cpu_count()} cores; {args.threads} threads; "
          f"box filter of one pixel; medians of {args.repeats} interleaved runs; load "
          f"{os.getloadavg()[0]:.1f} at the end. Cycles adaptive: threshold "
          f"{CYCLES_ADAPTIVE}; vs Cycles' better: against "
          + ", ".join(f"{r['scene']}: {r['best_cycles']}" for r in results) + ".\n")
    print(table(results))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
