"""Make the Tamaas reference fixture for the tangential tests in tests/slide_tamaas.rs (needs
`pip install tamaas`; made with Tamaas 2.9.0, whose licence is the AGPL-3.0: the fixture holds
its output only, none of its code).

What Tamaas 2.9's PolonskyKeerTan solves on a surface_2d model (found by probing its operator
and checking its solution, below): the three traction components t = (q, p) on a periodic
grid, one shot from the unloaded state, with
- the coupled Boussinesq–Cerruti operator u = K t, zero mode zero (displacements from the mean);
  the coupling (tangential displacement from pressure and normal from shear) carries (1 − 2ν);
- the normal contact conditions p ≥ 0, gap ≥ 0, p · gap = 0 (no dilatancy: slipping points
  stay in contact with zero gap);
- Coulomb's cone |q| ≤ μ p; a stuck point has u_t = δ, a slipping point |q| = μ p with
  u_t − δ opposite to q, δ the rigid tangential displacement, both components free (Lagrange
  multipliers of the imposed mean traction (q_x, q_y, p));
- its component 0 along the array's first axis (rows: asperity's y), component 1 along the
  second (columns: asperity's x). The fixture stores the fields in asperity's order.

Given Tamaas' pressure, that is asperity's tangential problem (target δ, one increment from
the unloaded state) with two differences: the coupling's tangential displacement of the
pressure, C p, which this script stores (from Tamaas' own operator, `coupling_*`), and the
cross term of Cerruti's kernel on the Nyquist lines (Tamaas takes k_y = −n/2 on the row
y = n/2 of its spectrum; asperity the mean of ±n/2, i.e. zero, which keeps the reflection
symmetry y → −y), whose displacement for Tamaas' traction this script stores too
(`nyquist_*`, a field (−1)^y g(x), as its row g). At ν = 0 the cross term vanishes (B = ν/G), so
with C p in its target asperity solves exactly Tamaas' problem.

Tamaas' error measure stalls between 3e-9 and 6e-8 (at ν = 0.5 its cost stops changing after
~2000 iterations and the error stays at 2.8e-9 up to 20000), so the solve stops at max_iter;
the conditions above, checked here with Tamaas' own operator, hold to 1e-12 of δ (residuals in
meta.json). The grid is even: on an odd one Tamaas gives the row (n − 1)/2 of its spectrum the
wavenumber −(n + 1)/2 instead of (n − 1)/2.

    python3 tools/make_tamaas_tangential_fixture.py
"""
import numpy as np
import tamaas as tm

from tamaas_fixture import fixture_dir, rough_surface, write_meta

N = 64
L = 6.4e-6
E = 130e9
MU = 0.3
MEAN_PRESSURE = 2e8  # Pa
RATIO = 0.5  # Q / (μ N), along asperity's x (Tamaas' component 1)
POISSON = [0.0, 0.26, 0.5]
MAX_ITER = 3000


def checks(t, u, h):
    """Residuals of the contact conditions of Tamaas' solution, with its own displacement."""
    p, q = t[..., 2], t[..., :2]
    qn = np.hypot(q[..., 0], q[..., 1])
    c = p > 0
    ratio = np.where(c, qn / np.where(c, p, 1.0), 0.0)
    slip = c & (ratio > MU * (1 - 1e-9))
    stick = c & ~slip
    delta = u[..., :2][stick].mean(axis=0)
    scale = np.hypot(*delta)
    d = u[..., :2] - delta
    dn = np.hypot(d[..., 0], d[..., 1])
    gap = u[..., 2] - h
    gap0 = gap[c].mean()
    along = (d[..., 0] * q[..., 0] + d[..., 1] * q[..., 1]) / np.maximum(dn * qn, 1e-300)
    return delta, {
        "stick_points": int(stick.sum()),
        "slip_points": int(slip.sum()),
        "stick_displacement_spread": float(np.abs(d[stick]).max() / scale),
        "normal_gap_spread_on_contact": float(np.abs(gap[c] - gap0).max() / scale),
        "least_gap_off_contact": float((gap[~c] - gap0).min() / scale),
        "largest_cone_ratio": float(ratio.max() / MU),
        "slip_against_traction_worst_cosine": float(along[slip & (dn > 1e-6 * scale)].max()),
    }


def main():
    out = fixture_dir("tamaas_tangential")
    for old in out.glob("*.npy"):
        old.unlink()
    h = rough_surface((N, N), 24)
    h = h * 5e-9 / h.std()
    np.save(out / "heights.npy", h)
    cases = []
    for k, nu in enumerate(POISSON):
        model = tm.ModelFactory.createModel(tm.model_type.surface_2d, [L, L], [N, N])
        model.E, model.nu = E, nu
        solver = tm.PolonskyKeerTan(model, h, 1e-12, MU)
        solver.max_iter = MAX_ITER
        solver.dump_freq = 100000
        error = solver.solve([0.0, RATIO * MU * MEAN_PRESSURE, MEAN_PRESSURE])
        t = np.array(model.traction).reshape(N, N, 3).copy()
        u = np.array(model.displacement).reshape(N, N, 3).copy()
        delta, residuals = checks(t, u, h)
        fields = {"shear_x": t[..., 1], "shear_y": t[..., 0], "pressure": t[..., 2]}
        if nu < 0.5:
            # The tangential displacement of the pressure alone (the coupling), Tamaas' operator.
            model.traction[...] = 0.0
            model.traction[..., 2] = t[..., 2]
            model.solveNeumann()
            v = np.array(model.displacement).reshape(N, N, 3)
            fields.update({"coupling_x": v[..., 1], "coupling_y": v[..., 0]})
        if nu > 0.0:
            # Tamaas' cross term on the Nyquist row (k_y = -n/2 where asperity has zero), for
            # its own traction: the off-diagonal response of its operator to the traction's
            # Nyquist-row part, a field (-1)^y g(x), stored as its row y = 0.
            sign = (-1.0) ** np.arange(N)[:, None, None]
            nyquist = sign * (sign * t[..., :2]).mean(axis=0)
            extra = {}
            for source, response in ((0, 1), (1, 0)):
                model.traction[...] = 0.0
                model.traction[..., source] = nyquist[..., source]
                model.solveNeumann()
                v = np.array(model.displacement).reshape(N, N, 3)[..., response]
                assert np.allclose(v, sign[:, :, 0] * v[0], rtol=0, atol=1e-12 * np.abs(v).max())
                extra[response] = v[:1]
            fields.update({"nyquist_x": extra[1], "nyquist_y": extra[0]})
        names = {}
        for field, values in fields.items():
            names[field] = f"{field}-{k:03}.npy"
            np.save(out / names[field], np.ascontiguousarray(values))
        cases.append({"poisson": nu, "error": error, "contact_points": int((t[..., 2] > 0).sum()),
                      "displacement_m": [float(delta[1]), float(delta[0])], **residuals, **names})
    write_meta(out, {"licence": "Tamaas is AGPL-3.0; these are its outputs",
                     "model": "surface_2d", "solver": "PolonskyKeerTan", "tolerance": 1e-12,
                     "max_iter": MAX_ITER, "grid": [N, N], "physical_size_m": [L, L], "youngs_pa": E,
                     "mu": MU, "axes": "asperity's: x along columns (Tamaas' component 1), y along rows",
                     "mean_traction_pa": [RATIO * MU * MEAN_PRESSURE, 0.0, MEAN_PRESSURE], "cases": cases})


if __name__ == "__main__":
    main()
