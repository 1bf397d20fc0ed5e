#!/usr/bin/env python3
"""hairtrace against Blender Cycles on the bench scenes, on this machine, in one run.

    bench/peer [--quick] [--scenes fur_ball,scalp] [--repeats 3] [--threads 2] [--time-to-rmse]
    bench/peer --scenes 'real_*_close_*'       # names or shell patterns, comma-separated
    bench/peer --exclude 'real_*'              # the procedural scenes alone

(bench/peer sets up the virtual environment, builds hairtrace and the ray-counting shim,
then runs this file.) Scenes that read real grooms (`target/real-grooms/STYLE/...`) get
them made first by bench/real_grooms.py when they are missing. For each scene of
bench/scenes/:

1. `hairtrace export` writes the scene for Cycles (bench/cycles.py reads it).
2. A reference: each renderer renders it at `REFERENCE_FACTOR` x the scene's spp with a
   seed no timed render uses (a render sharing the reference's seed shares its first
   samples and its RMSE comes out too low). The reference is the mean of the two, so
   neither renderer is measured against its own bias; the distance between the two
   (converged difference) is reported against the noise the two references carry.
3. Timed renders at the scene's spp, hairtrace and Cycles interleaved, `--repeats` times
   with different seeds: path-tracing seconds (scene build or sync excluded), the whole
   wait (hairtrace: its process, start to written image; Cycles: the scene read into
   Blender, synced, built, rendered and written), camera samples per second, rays per
   camera sample, RMSE against the reference, efficiency 1 / (RMSE^2 x seconds) on each
   of the two times. Medians are reported. Cycles renders twice, with its adaptive
   sampling off and on at Blender's default threshold (`CYCLES_ADAPTIVE`, the spp then
   its most samples); hairtrace is compared with the better of the two on each scene, and
   the table says which. hairtrace renders with the scene's own settings (its
   `allocation` among them); `--allocation` renders it once more with that allocation, and
   `--set NAME=VALUE` (repeatable) once more with those settings.
4. `--time-to-rmse`: each renderer's time to one RMSE, hairtrace stopping by its noise
   target, Cycles by its adaptive threshold (`time_to_rmse`), with hairtrace's estimated
   noise beside the measured one.

RMSE against the mean of two references needs no pixel arithmetic here: for images x, a,
b, |x - (a + b)/2|^2 = |x - a|^2 / 2 + |x - b|^2 / 2 - |a - b|^2 / 4 per pixel, so the
mean squared errors against a, b and between a and b (from `hairtrace compare`) give it
exactly.
"""

import argparse
import fnmatch
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import time
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The binary measured: $HT_HAIRTRACE (`hairtrace report` passes its own) or the release
# build. main() links or copies it into the work folder first and runs that, so that a build
# during a run (hours, for the real grooms) cannot change the renderer under it.
HAIRTRACE = os.environ.get("HT_HAIRTRACE") or os.path.join(ROOT, "target", "release", "hairtrace")
CYCLES = os.path.join(ROOT, "bench", "cycles.py")
SCENES = os.path.join(ROOT, "bench", "scenes")
# Grooms made by Blender's hair node assets (bench/real_grooms.py), on demand, never committed.
REAL_GROOMS = os.path.join(ROOT, "target", "real-grooms")
REAL_GROOMS_MAKER = os.path.join(ROOT, "bench", "real_grooms.py")
REFERENCE_SEED = 1_000_003
REFERENCE_FACTOR = 16
# Blender's default noise threshold for Cycles' adaptive sampling.
CYCLES_ADAPTIVE = 0.01
# The thresholds `--time-to-rmse` tries, coarsest first, until one reaches hairtrace's RMSE.
CYCLES_LADDER = (0.8, 0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625)


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

    def hairtrace(self, spp, seed, out, allocation=None, noise_target=None, settings=()):
        stats = out + ".json"
        extra = ["--allocation", allocation] if allocation else []
        for setting in settings:
            extra += ["--set", setting]
        if noise_target:
            extra += ["--noise-target", repr(noise_target)]
        start = time.perf_counter()
        run([HAIRTRACE, "render", self.path, "--spp", str(spp), "--seed", str(seed),
             "--threads", str(self.threads), "--max-depth", str(self.max_depth),
             "--filter", "box", "-o", out, "--stats", stats] + extra)
        wait = time.perf_counter() - start
        with open(stats) as f:
            s = json.load(f)
        return {"seconds": s["seconds"], "wait": wait, "samples": s["samples"], "rays": s["rays"],
                "spp": s["spp"], "noise": s["noise"]}

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
        return {"seconds": s["render_seconds"], "wait": s["wait_seconds"],
                "samples": s["samples"], "rays": rays}


class Reference:
    """The two references of a scene, and the RMSE of an image against their mean."""

    def __init__(self, scene, log):
        self.spp = scene.spp * REFERENCE_FACTOR
        self.paths = {}
        for name, render in (("hairtrace", scene.hairtrace), ("Cycles", scene.cycles)):
            self.paths[name] = os.path.join(scene.work, f"reference-{name}.exr")
            t = time.time()
            render(self.spp, REFERENCE_SEED, self.paths[name])
            log(f"  {name} reference, {self.spp} spp: {time.time() - t:.0f} s wall")
        self.mse_ab, self.mean_hairtrace, self.mean_cycles = mse(
            self.paths["hairtrace"], self.paths["Cycles"])

    def rmse(self, image):
        """RMSE against the mean of the references, and the image's mean."""
        ea, mean, _ = mse(image, self.paths["hairtrace"])
        eb, _, _ = mse(image, self.paths["Cycles"])
        return math.sqrt(max(0.0, (ea + eb) / 2 - self.mse_ab / 4)), mean


def measure(scene, ref, repeats, allocation, settings, log):
    renderers = {"hairtrace": scene.hairtrace, "Cycles": scene.cycles}
    if allocation:
        renderers[f"hairtrace allocation {allocation}"] = (
            lambda spp, seed, out: scene.hairtrace(spp, seed, out, allocation))
    if settings:
        renderers["hairtrace " + " ".join(settings)] = (
            lambda spp, seed, out: scene.hairtrace(spp, seed, out, settings=settings))
    renderers["Cycles adaptive"] = (
        lambda spp, seed, out: scene.cycles(spp, seed, out, CYCLES_ADAPTIVE))
    runs = {name: [] for name in renderers}
    for seed in range(1, repeats + 1):
        for name, render in renderers.items():
            out = os.path.join(scene.work, f"{name.replace(' ', '-')}-{seed}.exr")
            r = render(scene.spp, seed, out)
            r["rmse"], r["mean"] = ref.rmse(out)
            runs[name].append(r)
            log(f"  {name} seed {seed}: {r['seconds']:.3f} s ({r['wait']:.3f} s whole wait), "
                f"RMSE {r['rmse']:.5f}")
    rows = {}
    for name, rs in runs.items():
        seconds = statistics.median(r["seconds"] for r in rs)
        wait = statistics.median(r["wait"] for r in rs)
        rmse = statistics.median(r["rmse"] for r in rs)
        rays = [r["rays"] / r["samples"] for r in rs if r["rays"] is not None]
        rows[name] = {
            "seconds": seconds,
            "samples_per_second": rs[0]["samples"] / seconds,
            "rays_per_sample": statistics.median(rays) if rays else None,
            "rmse": rmse,
            "efficiency": 1.0 / (rmse * rmse * seconds),
            "wait_seconds": wait,
            "wait_efficiency": 1.0 / (rmse * rmse * wait),
            "runs": rs,
        }
    # Each reference carries the noise of a timed render divided by REFERENCE_FACTOR in
    # variance; the two differ by both.
    expected = math.sqrt(sum(rows[n]["rmse"] ** 2 for n in ("hairtrace", "Cycles"))
                         / REFERENCE_FACTOR)
    best = max(("Cycles", "Cycles adaptive"), key=lambda n: rows[n]["efficiency"])
    best_wait = max(("Cycles", "Cycles adaptive"), key=lambda n: rows[n]["wait_efficiency"])
    converged = {
        "rmse_between_references": math.sqrt(ref.mse_ab),
        "expected_from_noise": expected,
        "mean_hairtrace": ref.mean_hairtrace,
        "mean_cycles": ref.mean_cycles,
    }
    return {"scene": scene.name, "spp": scene.spp, "reference_spp": ref.spp,
            "size": [scene.width, scene.height], "max_depth": scene.max_depth,
            "threads": scene.threads, "renderers": rows, "converged": converged,
            "best_cycles": best, "best_cycles_wait": best_wait}


def time_to_rmse(scene, ref, fixed, repeats, log):
    """Each renderer's time to the RMSE hairtrace's noise target reaches.

    hairtrace renders with `noise_target` set to the relative RMSE its fixed-spp renders had,
    and stops by its own estimate; its RMSE is then measured. Cycles renders with adaptive
    sampling down a ladder of thresholds until one reaches that RMSE, and its time there is
    interpolated in log-log between the two thresholds that bracket it. Both take the
    reference's spp as their most samples, so that neither stops on the cap. Cycles with
    adaptive sampling off is timed at that RMSE too, from its fixed-spp renders (variance in
    proportion to 1/spp), and the better of the two is the one compared.
    """
    h = fixed["renderers"]["hairtrace"]
    target = h["rmse"] / statistics.median(r["mean"] for r in h["runs"])
    runs = []
    for seed in range(1, repeats + 1):
        out = os.path.join(scene.work, f"hairtrace-noise-target-{seed}.exr")
        r = scene.hairtrace(ref.spp, seed, out, noise_target=target)
        r["rmse"], r["mean"] = ref.rmse(out)
        runs.append(r)
        log(f"  hairtrace noise target {target:.4f} seed {seed}: {r['seconds']:.3f} s, "
            f"{r['spp']} spp, RMSE {r['rmse']:.5f}, estimated {r['noise'] * r['mean']:.5f}")
    rmse = statistics.median(r["rmse"] for r in runs)
    ladder = []
    for threshold in CYCLES_LADDER:
        rs = []
        for seed in range(1, repeats + 1):
            out = os.path.join(scene.work, f"Cycles-threshold-{threshold}-{seed}.exr")
            r = scene.cycles(ref.spp, seed, out, threshold)
            r["rmse"], _ = ref.rmse(out)
            rs.append(r)
        step = {"threshold": threshold,
                "seconds": statistics.median(r["seconds"] for r in rs),
                "rmse": statistics.median(r["rmse"] for r in rs),
                "spp": statistics.median(r["samples"] for r in rs) / (scene.width * scene.height)}
        log(f"  Cycles threshold {threshold}: {step['seconds']:.3f} s, RMSE {step['rmse']:.5f}")
        ladder.append(step)
        if step["rmse"] <= rmse:
            break
    cycles_seconds = None
    if len(ladder) >= 2 and ladder[-1]["rmse"] <= rmse < ladder[-2]["rmse"]:
        a, b = ladder[-2], ladder[-1]
        f = math.log(rmse / a["rmse"]) / math.log(b["rmse"] / a["rmse"])
        cycles_seconds = math.exp(math.log(a["seconds"])
                                  + f * math.log(b["seconds"] / a["seconds"]))
    off = fixed["renderers"]["Cycles"]
    return {
        "noise_target": target,
        "cycles_off_seconds": off["seconds"] * (off["rmse"] / rmse) ** 2,
        "seconds": statistics.median(r["seconds"] for r in runs),
        "spp": statistics.median(r["spp"] for r in runs),
        "rmse": rmse,
        "estimated_rmse": statistics.median(r["noise"] * r["mean"] for r in runs),
        "runs": runs,
        "cycles_ladder": ladder,
        "cycles_seconds": cycles_seconds,
    }


def rmse_table(results):
    lines = [
        "| scene | noise target | hairtrace s | its spp | RMSE measured | RMSE estimated "
        "| estimated / measured | Cycles thresholds (RMSE, s) | Cycles adaptive s at that RMSE "
        "| Cycles off s at that RMSE | Cycles' better s / hairtrace s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for res in results:
        t = res["time_to_rmse"]
        ladder = ", ".join(f"{c['threshold']} ({c['rmse']:.5f}, {c['seconds']:.2f} s)"
                           for c in t["cycles_ladder"])
        adaptive = t["cycles_seconds"]
        best = min(s for s in (adaptive, t["cycles_off_seconds"]) if s is not None)
        cycles = "not bracketed" if adaptive is None else f"{adaptive:.2f}"
        lines.append(
            f"| {res['scene']} | {t['noise_target']:.4f} | {t['seconds']:.2f} | {t['spp']:.0f} "
            f"| {t['rmse']:.5f} | {t['estimated_rmse']:.5f} "
            f"| {t['estimated_rmse'] / t['rmse']:.2f} | {ladder} | {cycles} "
            f"| {t['cycles_off_seconds']:.2f} | {best / t['seconds']:.2f}x |")
    return "\n".join(lines)


def table(results):
    lines = [
        "| scene | renderer | path tracing s | camera samples/s | rays/sample | RMSE "
        "| efficiency 1/(RMSE²·s) | vs Cycles' better | whole wait s | vs Cycles' better, "
        "whole wait |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for res in results:
        # Against Cycles' better setting on this scene, adaptive sampling off or on.
        cycles = res["renderers"][res["best_cycles"]]["efficiency"]
        cycles_wait = res["renderers"][res["best_cycles_wait"]]["wait_efficiency"]
        w, h = res["size"]
        label = f"{res['scene']} ({w}x{h}, {res['spp']} spp)"
        for name, r in res["renderers"].items():
            rays = "n/a" if r["rays_per_sample"] is None else f"{r['rays_per_sample']:.2f}"
            lines.append(
                f"| {label} | {name} | {r['seconds']:.2f} | {r['samples_per_second'] / 1e6:.3f} M "
                f"| {rays} | {r['rmse']:.5f} | {r['efficiency']:.0f} "
                f"| {r['efficiency'] / cycles:.2f}x | {r['wait_seconds']:.2f} "
                f"| {r['wait_efficiency'] / cycles_wait:.2f}x |")
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


def select_scenes(patterns, exclude):
    """The scene names of bench/scenes/ that the comma-separated names or shell patterns
    choose (all when none), in their order, less those `exclude`'s patterns match."""
    names = sorted(f[:-5] for f in os.listdir(SCENES) if f.endswith(".toml"))
    chosen = []
    for pattern in (patterns.split(",") if patterns else ["*"]):
        matched = [n for n in names if fnmatch.fnmatchcase(n, pattern.strip())]
        if not matched:
            sys.exit(f"bench: --scenes {pattern!r} matches no scene of bench/scenes/ "
                     f"({', '.join(names)})")
        chosen += [n for n in matched if n not in chosen]
    for pattern in (exclude.split(",") if exclude else []):
        chosen = [n for n in chosen if not fnmatch.fnmatchcase(n, pattern.strip())]
    if not chosen:
        sys.exit("bench: --exclude leaves no scene")
    return chosen


def make_real_grooms(names, log):
    """Makes the real grooms (bench/real_grooms.py) that the scenes read and that are
    missing: a scene's groom or mesh file under target/real-grooms/STYLE/ names its style."""
    missing = set()
    for name in names:
        with open(os.path.join(SCENES, name + ".toml"), "rb") as f:
            scene = tomllib.load(f)
        for entry in scene.get("groom", []) + scene.get("mesh", []):
            if "file" not in entry:
                continue
            path = os.path.normpath(os.path.join(SCENES, entry["file"]))
            inside = os.path.relpath(path, REAL_GROOMS)
            if not inside.startswith(os.pardir) and not os.path.exists(path):
                missing.add(inside.split(os.sep)[0])
    if missing:
        styles = ",".join(sorted(missing))
        log(f"real grooms {styles}: making them with bench/real_grooms.py (a minute or two each)")
        t = time.time()
        out = run([sys.executable, REAL_GROOMS_MAKER, "--out", REAL_GROOMS, "--styles", styles])
        # Its summary, without Blender's own messages.
        log("\n".join(line for line in out.splitlines()
                      if line.split(":")[0] in missing or line.startswith("  /")))
        log(f"  {time.time() - t:.0f} s wall")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", help="comma-separated names from bench/scenes/, or shell "
                                         "patterns of them such as 'real_*' (default: all)")
    parser.add_argument("--exclude", help="comma-separated shell patterns of scenes to leave "
                                          "out, such as 'real_*_hd_*'")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--quick", action="store_true", help="a quarter of each scene's spp")
    parser.add_argument("--work", default=os.path.join(ROOT, "target", "bench-peer"))
    parser.add_argument("--shim", help="the ray-counting LD_PRELOAD library for Cycles")
    parser.add_argument("--json", help="also write the results here")
    parser.add_argument("--time-to-rmse", action="store_true",
                        help="also time each renderer to a given RMSE: hairtrace by its noise "
                             "target, Cycles by its adaptive threshold")
    parser.add_argument("--allocation", choices=["uniform", "noise"],
                        help="also render hairtrace with this allocation")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="also render hairtrace with this setting (repeatable: all at once)")
    args = parser.parse_args()
    names = select_scenes(args.scenes, args.exclude)
    global HAIRTRACE
    os.makedirs(args.work, exist_ok=True)
    own = os.path.join(args.work, "hairtrace")
    if not os.path.isfile(HAIRTRACE):
        sys.exit(f"bench: no hairtrace binary at {HAIRTRACE} (set HT_HAIRTRACE, or run "
                 "cargo build --release)")
    if os.path.abspath(HAIRTRACE) != own:
        # A hard link keeps the file a build unlinks (the linker writes a new one).
        try:
            os.link(HAIRTRACE, own + ".part")
        except OSError:
            shutil.copy2(HAIRTRACE, own + ".part")
        os.replace(own + ".part", own)
    HAIRTRACE = own

    def log(message):
        print(message, file=sys.stderr, flush=True)

    make_real_grooms(names, log)

    results = []
    for name in names:
        log(f"{name}:")
        scene = Scene(name, args.work, args)
        ref = Reference(scene, log)
        result = measure(scene, ref, args.repeats, args.allocation, args.set, log)
        if args.time_to_rmse:
            result["time_to_rmse"] = time_to_rmse(scene, ref, result, args.repeats, log)
        results.append(result)
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), platform.processor())
    print(f"Machine: {cpu}, {os.cpu_count()} cores; {args.threads} threads; "
          f"box filter of one pixel; medians of {args.repeats} interleaved runs; load "
          f"{os.getloadavg()[0]:.1f} at the end. Cycles adaptive: threshold "
          f"{CYCLES_ADAPTIVE}; vs Cycles' better: against "
          + ", ".join(f"{r['scene']}: {r['best_cycles']}" for r in results) + ".\n")
    print(table(results))
    if args.time_to_rmse:
        print("\nTime to a given RMSE (medians of the same seeds):\n")
        print(rmse_table(results))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
