#!/usr/bin/env python3
"""asperity against Tamaas on the paper's surface, in one run on one machine.

The surface: 1500 × 1500 points over 31.13 µm, self-affine roughness (H = 0.8, roll-off 5 µm,
22 nm RMS) on a sphere of radius 1.5 mm (≈ 40 nm RMS in all), made by `asperity topo generate`.
Silicon (E = 130 GPa, ν = 0.26) on a rigid flat, periodic, loads 0.1, 1, 10 and 100 mN.

For each load, each solver starts from scratch (a cold solve); then each sweeps the four loads
in one model, starting every solve from the previous one (Tamaas keeps its last pressure,
asperity warm-starts). Both solve to tolerance 1e-10 in their own residual; the relative L2
difference of their pressure maps shows that they agree. asperity's time per iteration is set
against the time of one FFT pair on the same grid (`cargo bench --bench contact`).

Needs Python with numpy and tamaas (`pip install tamaas`), and the Rust toolchain.

    python3 benches/compare_tamaas.py [--quick]

`--quick` uses a 512² grid (same physical size) to try the script out. Prints a Markdown
table and writes it, with the raw numbers, to benches/results/.
"""
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np
import tamaas as tm

from tamaas_common import LOADS, ROOT, SIZE, SURFACE, TOLERANCE, tamaas_model, tamaas_solve, write_results


def run(cmd, **kw):
    print("+", " ".join(map(str, cmd)), file=sys.stderr, flush=True)
    return subprocess.run([str(c) for c in cmd], check=True, cwd=ROOT, **kw)


def main():
    n = 512 if "--quick" in sys.argv else 1500
    tm.set_log_level(tm.LogLevel.warning)
    run(["cargo", "build", "--release", "--quiet"])
    work = pathlib.Path(tempfile.mkdtemp(prefix="asperity-bench-"))
    surface = work / "surface.npy"
    options = [x for k, v in SURFACE.items() for x in ("--" + k.replace("_", "-"), v)]
    run([ROOT / "target/release/asperity", "topo", "generate", "--size", SIZE, "--grid", n, *options, surface])
    h = np.load(surface)
    print(f"surface: {n}², {h.std() * 1e9:.1f} nm RMS", file=sys.stderr)

    env = dict(os.environ, TOLERANCE=str(TOLERANCE))
    out = run(["cargo", "bench", "--quiet", "--bench", "contact", "--", surface, SIZE, work, *LOADS],
              env=env, capture_output=True, text=True).stdout
    ours = json.loads(out[out.index("{"):])

    cold = []
    for k, load in enumerate(LOADS):
        model, solver = tamaas_model(h)
        seconds, p = tamaas_solve(model, solver, load)
        mine = np.load(work / f"asperity-{k:03}.npy")
        cold.append({
            "load_n": load, "seconds": seconds,
            "relative_l2_difference": float(np.linalg.norm(mine - p) / np.linalg.norm(p)),
            "contact_points": int((p > 0).sum()),
        })
        print(f"tamaas cold {load} N: {seconds:.1f} s", file=sys.stderr, flush=True)
    model, solver = tamaas_model(h)
    start = time.perf_counter()
    sweep = [tamaas_solve(model, solver, load)[0] for load in LOADS]
    tamaas_sweep = time.perf_counter() - start

    pair = ours["fft_pair_seconds"]
    lines = [
        f"Grid {n}², {ours['threads']} threads for asperity (Tamaas {tm.TamaasInfo.version}, backend "
        f"{tm.TamaasInfo.backend}), tolerance {TOLERANCE:g} for both; FFT pair {pair * 1e3:.1f} ms.",
        "",
        "| load | Tamaas cold | asperity cold | speed-up | iterations | s/iteration ÷ FFT pair | contact points "
        "| asperity vs Tamaas (rel. L2) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for a, t in zip(ours["cold"], cold):
        lines.append(
            f"| {a['load_n'] * 1e3:g} mN | {t['seconds']:.2f} s | {a['seconds']:.2f} s | "
            f"{t['seconds'] / a['seconds']:.1f}× | {a['iterations']} | "
            f"{a['seconds_per_iteration'] / pair:.2f} | {a['contact_points']} | {t['relative_l2_difference']:.1e} |")
    iterations = sum(s["iterations"] for s in ours["sweep"])
    lines.append(
        f"| sweep of 4 | {tamaas_sweep:.2f} s | {ours['sweep_seconds']:.2f} s | "
        f"{tamaas_sweep / ours['sweep_seconds']:.1f}× | {iterations} | "
        f"{ours['sweep_seconds'] / iterations / pair:.2f} | | |")
    write_results(f"contact-vs-tamaas-{n}", "\n".join(lines),
                  {"asperity": ours, "tamaas": {"cold": cold, "sweep_seconds": tamaas_sweep, "sweep": sweep}})


if __name__ == "__main__":
    main()
