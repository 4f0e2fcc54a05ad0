#!/usr/bin/env python3
"""A contact solve through the Python package against the same solve by the command line.

The paper's surface (as benches/compare_tamaas.py: 31.13 µm, H = 0.8, 22 nm RMS on a 1.5 mm
sphere, seed 1), silicon on a rigid flat, periodic, tolerance 1e-10, one load per run. Each
round runs `asperity contact` (a process: read the .npy, solve, write the pressure map) and
`asperity.contact` (a call: solve, copy the pressure and compute the gap) one after the other,
alternating which goes first, so that the drift of a shared machine hits both alike; the
ratio is taken within each round. Reported: the wall time of the process and of the call, and
the solver's own time (contact.json's `seconds`, `ContactSolution.seconds`).

Needs the package installed (`bash .ci/test` installs it into target/python) and the release
binary (`cargo build --release`):

    target/python/bin/python benches/python_vs_cli.py [--grid N] [--load N] [--rounds K]
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import tempfile
import time

import numpy as np

import asperity as ap

ROOT = pathlib.Path(__file__).resolve().parent.parent


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=1500)
    parser.add_argument("--load", type=float, default=1e-2, help="[N]")
    parser.add_argument("--rounds", type=int, default=6)
    args = parser.parse_args()
    cli = ROOT / "target/release/asperity"
    work = pathlib.Path(tempfile.mkdtemp(prefix="asperity-python-bench-"))
    t = ap.generate(size=31.13e-6, grid=args.grid, hurst=0.8, rms=22e-9, rolloff=5e-6, sphere_radius=1.5e-3, seed=1)
    np.save(work / "surface.npy", np.asarray(t.heights))
    lx, ly = t.physical_size

    def by_cli(k):
        out = work / f"cli-{k}"
        start = time.perf_counter()
        subprocess.run([cli, "contact", work / "surface.npy", "--size", f"{lx!r},{ly!r}", "--load", repr(args.load),
                        "--out", out], check=True, capture_output=True)
        wall = time.perf_counter() - start
        return wall, json.loads((out / "contact.json").read_text())["loads"][0]["seconds"], np.load(
            out / "pressure-000.npy")

    def by_python():
        start = time.perf_counter()
        (s,) = ap.contact(t, loads=args.load)
        return time.perf_counter() - start, s.seconds, s.pressure

    by_python()  # the first call loads nothing the later ones do not, but warms the caches alike
    rounds = []
    for k in range(args.rounds):
        if k % 2 == 0:
            c, p = by_cli(k), by_python()
        else:
            p, c = by_python(), by_cli(k)
        assert np.array_equal(c[2], p[2]), "the Python and command-line pressure maps differ"
        rounds.append({"cli_wall": c[0], "cli_solve": c[1], "python_wall": p[0], "python_solve": p[1]})
        print(f"round {k}: cli {c[0]:.3f} s (solve {c[1]:.3f} s), python {p[0]:.3f} s (solve {p[1]:.3f} s), "
              f"wall ratio {p[0] / c[0]:.3f}", flush=True)
    wall = [r["python_wall"] / r["cli_wall"] for r in rounds]
    solve = [r["python_solve"] / r["cli_solve"] for r in rounds]
    print(f"\ngrid {args.grid}², load {args.load} N, {args.rounds} interleaved rounds; identical pressure maps")
    print(f"python / cli, wall:  median {statistics.median(wall):.3f}, range {min(wall):.3f}–{max(wall):.3f}")
    print(f"python / cli, solve: median {statistics.median(solve):.3f}, range {min(solve):.3f}–{max(solve):.3f}")


if __name__ == "__main__":
    main()
