"""Make the Tamaas reference fixture for tests/contact_tamaas.rs (needs `pip install tamaas`).

A small periodic surface (self-affine roughness plus a spherical cap, heights in metres) is
solved with Tamaas 2.9's PolonskyKeerRey on a basic_2d model at three loads; the heights, the
pressure maps and the parameters are written to tests/fixtures/tamaas/. asperity's tests then
compare with them without Python.

    python3 tools/make_tamaas_fixture.py
"""
import numpy as np
import tamaas as tm

from tamaas_fixture import fixture_dir, rough_surface, write_meta

NY, NX = 96, 128
LX, LY = 8e-6, 6e-6
E, NU = 130e9, 0.26
RADIUS = 200e-6
LOADS = [2e-4, 2e-3, 2e-2]  # N


def surface():
    rough = rough_surface((NY, NX), 40)
    rough *= 5e-9 / rough.std()
    y = (np.arange(NY) + 0.5) * LY / NY - LY / 2
    x = (np.arange(NX) + 0.5) * LX / NX - LX / 2
    xx, yy = np.meshgrid(x, y)
    return rough - (xx**2 + yy**2) / (2 * RADIUS)


def main():
    out = fixture_dir("tamaas")
    h = surface()
    np.save(out / "heights.npy", h)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [LY, LX], [NY, NX])
    model.E, model.nu = E, NU
    solver = tm.PolonskyKeerRey(model, h, 1e-14)
    solver.max_iter = 100000
    files = []
    for k, load in enumerate(LOADS):
        solver.solve(load / (LX * LY))
        p = np.array(model.traction).reshape(NY, NX)
        name = f"pressure-{k:03}.npy"
        np.save(out / name, p)
        files.append({"load_n": load, "pressure_file": name, "contact_points": int((p > 0).sum())})
    write_meta(out, {"grid": [NY, NX], "physical_size_m": [LX, LY], "youngs_pa": E, "poisson": NU,
                     "tolerance": 1e-14, "loads": files})


if __name__ == "__main__":
    main()
