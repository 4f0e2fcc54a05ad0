"""Make the Tamaas adhesion fixture for tests/contact_adhesion.rs (needs `pip install tamaas`).

A small periodic self-affine surface (heights in metres) is solved with Tamaas 2.9's
PolonskyKeerRey on the gap (the primal and the constraint both the gap: the mean gap is
imposed), with its Maugis–Dugdale (MaugisAdhesionFunctional) and its exponential
(ExponentialAdhesionFunctional) cohesive law, one mean gap each; the heights, the traction and
gap maps and the parameters are written to tests/fixtures/tamaas_adhesion/. asperity's tests
then compare with them without Python.

    python3 tools/make_tamaas_adhesion_fixture.py
"""
import numpy as np
import tamaas as tm

from tamaas_fixture import fixture_dir, rough_surface, write_meta

NY, NX = 64, 64
LX, LY = 4e-6, 4e-6
E, NU = 130e9, 0.26
TOLERANCE = 1e-12
# Tamaas' parameters: surface_energy is the work of adhesion w [J/m²]; rho the Maugis-Dugdale
# range h0 = w/σ0 or the exponential range [m].
CASES = [
    {"law": "maugis", "work_j_m2": 0.5, "range_m": 5e-9, "mean_gap_m": 12e-9},
    {"law": "exponential", "work_j_m2": 0.5, "range_m": 5e-9, "mean_gap_m": 12e-9},
]


def main():
    out = fixture_dir("tamaas_adhesion")
    h = rough_surface((NY, NX), 16)
    h *= 5e-9 / h.std()
    np.save(out / "heights.npy", h)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [LY, LX], [NY, NX])
    model.E, model.nu = E, NU
    cases = []
    for k, case in enumerate(CASES):
        solver = tm.PolonskyKeerRey(model, h, TOLERANCE, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.gap)
        solver.max_iter = 100000
        functional = {"maugis": tm.MaugisAdhesionFunctional,
                      "exponential": tm.ExponentialAdhesionFunctional}[case["law"]](h)
        functional.parameters = {"rho": case["range_m"], "surface_energy": case["work_j_m2"]}
        solver.addFunctionalTerm(functional)
        solver.solve(case["mean_gap_m"])
        traction = np.array(model.traction).reshape(NY, NX)
        gap = np.array(model.displacement).reshape(NY, NX) - h
        name, gap_name = f"traction-{k:03}.npy", f"gap-{k:03}.npy"
        np.save(out / name, traction)
        np.save(out / gap_name, gap)
        cases.append({**case, "traction_file": name, "gap_file": gap_name, "load_n": float(traction.mean() * LX * LY),
                      "contact_points": int((gap <= 0).sum())})
    write_meta(out, {"grid": [NY, NX], "physical_size_m": [LX, LY], "youngs_pa": E, "poisson": NU,
                     "tolerance": TOLERANCE, "cases": cases})


if __name__ == "__main__":
    main()
