#!/usr/bin/env python3
"""Tamaas and asperity driven from one Python process, on the same surface and loads.

The surface is made by `asperity.generate` (the paper's: 31.13 µm square, H = 0.8, roll-off
5 µm, 22 nm RMS on a 1.5 mm sphere, seed 1) and handed, as the same numpy array, to both:
silicon (E = 130 GPa, ν = 0.26) on a rigid flat, periodic, tolerance 1e-10 in each solver's own
residual. Each load is solved cold by each; then each sweeps the loads in one model (Tamaas
keeps its last pressure, `asperity.contact` warm-starts). The relative L2 difference of the
pressure maps shows that they agree. Tamaas runs its C++ backend on one thread, asperity on
all cores. Interleaved per load, so the drift of a shared machine hits both alike.

Needs the package (`bash .ci/test` installs it into target/python) and `pip install tamaas`:

    target/python/bin/python benches/compare_tamaas_python.py [--grid N]

Prints a Markdown table and writes it, with the raw numbers, to benches/results/.
"""
import argparse
import os
import time

import numpy as np
import tamaas as tm

import asperity as ap
from tamaas_common import LOADS, POISSON, SIZE, SURFACE, TOLERANCE, YOUNGS, tamaas_model, tamaas_solve, write_results


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=1500)
    args = parser.parse_args()
    tm.set_log_level(tm.LogLevel.warning)
    t = ap.generate(size=SIZE, grid=args.grid, **SURFACE)
    h = np.array(t.heights)  # Tamaas wants a writeable array: a copy

    cold = []
    for load in LOADS:
        model, solver = tamaas_model(h)
        seconds, p = tamaas_solve(model, solver, load)
        start = time.perf_counter()
        (s,) = ap.contact(t, loads=load, youngs=YOUNGS, poisson=POISSON, tolerance=TOLERANCE)
        ours = time.perf_counter() - start
        cold.append({
            "load_n": load, "tamaas_seconds": seconds, "asperity_seconds": ours, "iterations": s.iterations,
            "contact_points": s.contact_points, "tamaas_contact_points": int((p > 0).sum()),
            "relative_l2_difference": float(np.linalg.norm(s.pressure - p) / np.linalg.norm(p)),
        })
        print(f"{load} N: tamaas {seconds:.2f} s, asperity {ours:.2f} s", flush=True)
    model, solver = tamaas_model(h)
    start = time.perf_counter()
    for load in LOADS:
        tamaas_solve(model, solver, load)
    tamaas_sweep = time.perf_counter() - start
    start = time.perf_counter()
    sweep = ap.contact(t, loads=LOADS, youngs=YOUNGS, poisson=POISSON, tolerance=TOLERANCE)
    asperity_sweep = time.perf_counter() - start

    lines = [
        f"Grid {args.grid}², one Python process: Tamaas {tm.TamaasInfo.version} (backend {tm.TamaasInfo.backend}) "
        f"and asperity {ap.__version__} on the same numpy array; tolerance {TOLERANCE:g} for both.",
        "",
        "| load | Tamaas cold | asperity cold | speed-up | iterations | contact points (asperity / Tamaas) "
        "| asperity vs Tamaas (rel. L2) |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in cold:
        lines.append(
            f"| {c['load_n'] * 1e3:g} mN | {c['tamaas_seconds']:.2f} s | {c['asperity_seconds']:.2f} s | "
            f"{c['tamaas_seconds'] / c['asperity_seconds']:.1f}× | {c['iterations']} | "
            f"{c['contact_points']} / {c['tamaas_contact_points']} | {c['relative_l2_difference']:.1e} |")
    lines.append(
        f"| sweep of {len(LOADS)} | {tamaas_sweep:.2f} s | {asperity_sweep:.2f} s | "
        f"{tamaas_sweep / asperity_sweep:.1f}× | {sum(s.iterations for s in sweep)} | | |")
    # Per core (RAYON_NUM_THREADS=1, as the serial Tamaas wheel) apart from all cores.
    threads = os.environ.get("RAYON_NUM_THREADS")
    stem = f"python-tamaas-{args.grid}" + (f"-{threads}thread" if threads else "")
    write_results(stem, "\n".join(lines),
                  {"cold": cold, "tamaas_sweep_seconds": tamaas_sweep, "asperity_sweep_seconds": asperity_sweep})


if __name__ == "__main__":
    main()
