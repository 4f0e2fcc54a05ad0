"""Make the Tamaas reference fixture for the tangential tests in tests/slide_tamaas.rs (needs
`pip install tamaas`).

Tamaas 2.9's PolonskyKeerTan on a surface_2d model solves the normal and the tangential
problem together: the three traction components on a periodic surface, Coulomb's cone
|q| ≤ μ p, the mean traction (q_x, q_y, p) imposed (force control), in one shot from an
unloaded state, with the full Boussinesq–Cerruti operator — including the normal–tangential
coupling, whose terms carry (1 − 2ν). asperity solves the tangential problem on the pressure
of the normal solve, uncoupled, displacement-controlled and incrementally. The fixture covers
ν = 0.26 (silicon: coupled, the formulations differ), 0.4 and 0.5 (incompressible: the
coupling vanishes and both solve the same problem).

    python3 tools/make_tamaas_tangential_fixture.py
"""
import json
import pathlib

import numpy as np
import tamaas as tm

OUT = pathlib.Path(__file__).resolve().parent.parent / "tests" / "fixtures" / "tamaas_tangential"
N = 64
L = 6.4e-6
E = 130e9
MU = 0.3
MEAN_PRESSURE = 2e8  # Pa
RATIO = 0.5  # Q / (μ N)
POISSON = [0.26, 0.4, 0.5]


def surface():
    gen = tm.SurfaceGeneratorFilter2D([N, N])
    gen.random_seed = 7
    gen.spectrum = tm.Isopowerlaw2D()
    gen.spectrum.q0, gen.spectrum.q1, gen.spectrum.q2 = 2, 4, 24
    gen.spectrum.hurst = 0.8
    h = np.array(gen.buildSurface())
    return h * 5e-9 / h.std()


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    h = surface()
    np.save(OUT / "heights.npy", h)
    cases = []
    for k, nu in enumerate(POISSON):
        model = tm.ModelFactory.createModel(tm.model_type.surface_2d, [L, L], [N, N])
        model.E, model.nu = E, nu
        solver = tm.PolonskyKeerTan(model, h, 1e-12, MU)
        solver.max_iter = 20000
        solver.dump_freq = 100000
        error = solver.solve([RATIO * MU * MEAN_PRESSURE, 0.0, MEAN_PRESSURE])
        t = np.array(model.traction).reshape(N, N, 3)
        names = {}
        for c, field in enumerate(["shear_x", "shear_y", "pressure"]):
            names[field] = f"{field}-{k:03}.npy"
            np.save(OUT / names[field], np.ascontiguousarray(t[..., c]))
        cases.append({"poisson": nu, "error": error, "contact_points": int((t[..., 2] > 0).sum()), **names})
    meta = {"tamaas": tm.TamaasInfo.version, "model": "surface_2d", "solver": "PolonskyKeerTan",
            "grid": [N, N], "physical_size_m": [L, L], "youngs_pa": E, "mu": MU,
            "mean_traction_pa": [RATIO * MU * MEAN_PRESSURE, 0.0, MEAN_PRESSURE], "cases": cases}
    (OUT / "meta.json").write_text(json.dumps(meta, indent=1) + "\n")
    print(json.dumps(meta, indent=1))


if __name__ == "__main__":
    main()
