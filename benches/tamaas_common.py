"""What the Tamaas comparisons (compare_tamaas.py, compare_tamaas_python.py) share: the paper's
surface and material, Tamaas's model and solve, and where the results go."""
import json
import pathlib
import time

import numpy as np
import tamaas as tm

ROOT = pathlib.Path(__file__).resolve().parent.parent
SIZE = 31.13e-6
# The paper's roughness on a sphere (`asperity topo generate` options, `asperity.generate`
# keywords).
SURFACE = {"hurst": 0.8, "rms": 22e-9, "rolloff": 5e-6, "sphere_radius": 1.5e-3, "seed": 1}
LOADS = [1e-4, 1e-3, 1e-2, 1e-1]
YOUNGS, POISSON = 130e9, 0.26
TOLERANCE = 1e-10


def tamaas_model(h):
    """A Tamaas model of silicon on a rigid flat over `h`, and its solver."""
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [SIZE, SIZE], list(h.shape))
    model.E, model.nu = YOUNGS, POISSON
    solver = tm.PolonskyKeerRey(model, h, TOLERANCE)
    solver.max_iter = 100_000
    return model, solver


def tamaas_solve(model, solver, load):
    """Seconds to solve at `load` [N], and the pressure map."""
    start = time.perf_counter()
    solver.solve(load / SIZE**2)
    return time.perf_counter() - start, np.array(model.traction).copy()


def write_results(stem, table, raw):
    """Print the Markdown `table` and write it, with the `raw` numbers, to benches/results/."""
    print(table)
    results = ROOT / "benches/results"
    results.mkdir(exist_ok=True)
    (results / f"{stem}.md").write_text(table + "\n")
    (results / f"{stem}.json").write_text(json.dumps(raw, indent=1) + "\n")
