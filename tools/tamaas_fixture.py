"""What the Tamaas fixture scripts share (make_tamaas_fixture.py, make_tamaas_tangential_fixture.py):
the fixture folder, the self-affine surface both solve, and meta.json. Needs `pip install tamaas`."""
import json
import pathlib

import numpy as np
import tamaas as tm

FIXTURES = pathlib.Path(__file__).resolve().parent.parent / "tests" / "fixtures"


def fixture_dir(name):
    """tests/fixtures/NAME, created if missing."""
    out = FIXTURES / name
    out.mkdir(parents=True, exist_ok=True)
    return out


def rough_surface(shape, q2):
    """Tamaas' isotropic power-law surface on `shape` (rows, columns), unscaled (each fixture
    scales it to 5 nm RMS as it always did, so that regenerated heights keep their bits): seed 7,
    wavenumbers q0 = 2, q1 = 4 (roll-off), q2 (cut-off), Hurst exponent 0.8."""
    gen = tm.SurfaceGeneratorFilter2D(list(shape))
    gen.random_seed = 7
    gen.spectrum = tm.Isopowerlaw2D()
    gen.spectrum.q0, gen.spectrum.q1, gen.spectrum.q2 = 2, 4, q2
    gen.spectrum.hurst = 0.8
    return np.array(gen.buildSurface())


def write_meta(out, meta):
    """meta.json in `out`, with the Tamaas version first, also printed."""
    meta = {"tamaas": tm.TamaasInfo.version, **meta}
    (out / "meta.json").write_text(json.dumps(meta, indent=1) + "\n")
    print(json.dumps(meta, indent=1))
