"""The Python package's batched BSDF eval against the Rust batch, per evaluation, at 10^6
inputs: each side's median of 15 calls, the two run alternately (docs/measurements.md,
"The Python package"). Run from the repository, after scripts/python:

    target/python-venv/bin/python python/bench/bsdf_batch.py [ROUNDS]
"""

import os
import pathlib
import subprocess
import sys
import time

import numpy as np

import hairtrace

N = 1_000_000
CALLS = 15
REPO = pathlib.Path(__file__).resolve().parents[2]


def python_ns() -> float:
    rng = np.random.default_rng(1)
    unit = lambda v: (v / np.linalg.norm(v, axis=1, keepdims=True)).astype(np.float32)
    h = np.linspace(-1, 1, N, dtype=np.float32)
    wo, wi = unit(rng.normal(size=(N, 3))), unit(rng.normal(size=(N, 3)))
    bsdf = hairtrace.HairBsdf()
    times = []
    for _ in range(CALLS):
        t = time.perf_counter()
        bsdf.eval(h, wo, wi)
        times.append((time.perf_counter() - t) * 1e9 / N)
    return float(np.median(times))


def rust_ns() -> float:
    env = dict(os.environ, CARGO_BUILD_JOBS=os.environ.get("CARGO_BUILD_JOBS", "1"))
    out = subprocess.run(
        ["cargo", "bench", "-q", "-p", "hairtrace-benches", "--bench", "bsdf_batch"],
        cwd=REPO, env=env, check=True, capture_output=True, text=True,
    ).stdout
    return float(out.split()[-1])


def main() -> None:
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    py, rs = [], []
    for i in range(rounds):
        rs.append(rust_ns())
        py.append(python_ns())
        print(f"round {i}: rust {rs[-1]:.2f} ns, python {py[-1]:.2f} ns", flush=True)
    r, p = float(np.median(rs)), float(np.median(py))
    print(f"median of {rounds}: rust {r:.2f} ns/eval, python {p:.2f} ns/eval, ratio {p / r:.3f}")


if __name__ == "__main__":
    main()
