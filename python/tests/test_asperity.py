"""The Python package against closed forms, the command line, and its own error paths.

The comparisons with the command line run the `asperity` binary: $ASPERITY_CLI, or
target/release/asperity of this checkout (`.ci/test` builds it first and sets the variable).
"""

import ast
import inspect
import io
import json
import math
import re
import warnings
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import asperity as ap
from conftest import cli

ROOT = Path(__file__).resolve().parents[2]


def run_cli(*args):
    done = subprocess.run([cli(), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout


def rough_ball(grid=128, seed=1):
    """A small version of the default study's ball: 31.13 µm square, H = 0.8, on a 1.5 mm sphere."""
    return ap.generate(size=31.13e-6, grid=grid, hurst=0.8, rms=22e-9, rolloff=5e-6, sphere_radius=1.5e-3, seed=seed)


# --- closed forms -----------------------------------------------------------------------------


def test_hertz_contact_radius_and_peak_pressure():
    # A paraboloid of radius R on a free half-space, E* = E (ν = 0): a = (3NR/4E*)^⅓, p0 = 3N/(2πa²).
    r, e_star, a_hertz = 1e-3, 1e11, 10e-6
    load = 4 * e_star * a_hertz**3 / (3 * r)
    t = ap.generate(size=40e-6, grid=128, sphere_radius=r, paraboloid=True, seed=0)
    (s,) = ap.contact(t, loads=load, youngs=e_star, poisson=0.0, boundary="free")
    a = math.sqrt(s.contact_area / math.pi)
    p0 = 3 * load / (2 * math.pi * a_hertz**2)
    assert abs(a / a_hertz - 1) < 0.02, (a, a_hertz)
    assert abs(s.pressure.max() / p0 - 1) < 0.02, (s.pressure.max(), p0)
    dx, dy = t.pixel_size
    assert abs(s.pressure.sum() * dx * dy / load - 1) < 1e-10
    assert s.patches == 1 and s.boundary == "free"
    assert s.gap[s.pressure > 0].max() == 0.0 and s.gap.min() >= 0.0
    assert s.gap[0, 0] > 0.0


def test_single_element_gives_the_local_drop():
    p = np.zeros((4, 5))
    p[2, 3] = 7e8
    o = ap.onset(p, physical_size=(5e-6, 4e-6), mu_s=0.6, mu_d=0.4)
    assert o.friction_drop == pytest.approx(0.6 / 0.4, rel=1e-15)
    assert o.static_coefficient == pytest.approx(0.6, rel=1e-15)
    assert o.elements == 1 and o.critical.count == 1 and o.pre_sliding.count == 0
    assert o.normal_force == pytest.approx(7e8 * 1e-12, rel=1e-14)
    assert o.classes[2, 3] == 2 and o.classes.sum() == 2


@pytest.mark.parametrize(
    "n1, n2, pre_sliding",
    [
        (1.0, 3.0, 1),  # F_1 = mu_d n1 + mu_s n2 = 2.2 beats F_0 = 2 mu_s n1 = 1.2: n1 slips first
        (2.0, 2.5, 0),  # F_0 = 2 mu_s n1 = 2.4 beats F_1 = 0.8 + 1.5 = 2.3: n2 is subcritical
    ],
)
def test_two_elements_of_the_paper(n1, n2, pre_sliding):
    mu_s, mu_d = 0.6, 0.4
    p = np.array([[0.0, n1], [n2, 0.0]])
    o = ap.onset(p, pixel_area=1.0, mu_s=mu_s, mu_d=mu_d)
    f_s = max(2 * mu_s * n1, mu_d * n1 + mu_s * n2)
    assert o.static_force == pytest.approx(f_s, rel=1e-15)
    assert o.friction_drop == pytest.approx(f_s / (mu_d * (n1 + n2)), rel=1e-15)
    assert o.friction_drop < mu_s / mu_d
    assert o.pre_sliding.count == pre_sliding
    assert o.subcritical.count == 1 - pre_sliding
    assert o.critical.count == 1
    expected = [[0, 1], [2, 0]] if pre_sliding else [[0, 2], [3, 0]]
    if not pre_sliding:
        assert o.stress_ratio()[1, 0] == pytest.approx(mu_s * n1 / n2, rel=1e-15)
    assert o.classes.tolist() == expected
    c = o.curve()
    assert c["force_n"][c["peak"]] == pytest.approx(f_s, rel=1e-15)
    assert c["coefficient"][c["peak"]] == pytest.approx(o.static_coefficient, rel=1e-15)


# --- numpy in and out, against the command line -------------------------------------------------


def test_arrays_are_float64_ny_by_nx_row_y():
    h = np.arange(12, dtype=np.float64).reshape(3, 4) * 1e-9  # 3 rows (y), 4 columns (x)
    t = ap.Topography(h, physical_size=(4e-6, 3e-6))
    assert t.shape == (3, 4) and t.pixel_size == (1e-6, 1e-6)
    assert t.heights.dtype == np.float64 and np.array_equal(t.heights, h)
    assert not t.heights.flags.writeable and t.heights.base is not None  # a view, no copy
    ints = ap.Topography([[1, 2], [3, 4]], physical_size=1e-6)  # any array-like
    assert ints.heights.dtype == np.float64 and ints.heights[1, 0] == 3.0
    cropped = t.crop(columns=(1, 3), rows=(0, 2))
    assert np.array_equal(cropped.heights, h[0:2, 1:3])
    physical = t.crop(x=(1e-6, 3e-6), y=(0, 2e-6))
    assert np.array_equal(physical.heights, h[0:2, 1:3])


def test_a_npy_round_trip_keeps_orientation(tmp_path):
    h = np.random.default_rng(3).normal(size=(6, 9)) * 1e-9
    np.save(tmp_path / "h.npy", h)
    t = ap.read_topography(tmp_path / "h.npy", size=(9e-6, 6e-6))
    assert np.array_equal(t.heights, h) and t.physical_size == (9e-6, 6e-6)
    assert t.channels == [t.channel] and t.file == tmp_path / "h.npy"


def test_generate_matches_the_command_line_bit_for_bit(tmp_path):
    out = tmp_path / "ball.npy"
    run_cli("topo", "generate", "--size", "31.13e-6", "--grid", "96,64", "--hurst", "0.8", "--rms", "22e-9",
            "--rolloff", "5e-6", "--sphere-radius", "1.5e-3", "--seed", "7", out)
    t = ap.generate(size=31.13e-6, grid=(96, 64), hurst=0.8, rms=22e-9, rolloff=5e-6, sphere_radius=1.5e-3, seed=7)
    h = np.load(out)
    assert h.dtype == np.float64 and h.shape == t.shape == (64, 96)
    assert np.array_equal(t.heights, h)
    text = run_cli("topo", "psd", out, "--size", "31.13e-6,20.752e-6")
    assert text.startswith("q_rad_per_m,psd_m4")


def test_contact_matches_the_command_line_bit_for_bit(tmp_path):
    t = rough_ball(grid=(96, 80))
    np.save(tmp_path / "h.npy", np.asarray(t.heights))
    lx, ly = t.physical_size
    loads = [3e-3, 1e-4, 1e-3]  # given out of order: solved in increasing order, returned as given
    run_cli("contact", tmp_path / "h.npy", "--size", f"{lx!r},{ly!r}", *(f"--load={l!r}" for l in loads),
            "--fields", "--out", tmp_path / "out")
    record = json.loads((tmp_path / "out" / "contact.json").read_text())
    sols = ap.contact(t, loads=loads)
    for k, (s, entry) in enumerate(zip(sols, record["loads"])):
        p = np.load(tmp_path / "out" / f"pressure-{k:03}.npy")
        assert p.dtype == s.pressure.dtype == np.float64 and p.shape == s.pressure.shape == (80, 96)
        assert np.array_equal(p, s.pressure), f"load {loads[k]}"
        assert np.array_equal(np.load(tmp_path / "out" / f"gap-{k:03}.npy"), s.gap)
        assert s.load == entry["load_n"] == loads[k]
        assert (s.contact_points, s.patches, s.iterations) == (
            entry["contact_points"], entry["patches"], entry["iterations"])
        assert s.contact_fraction == entry["contact_fraction"] and s.residual == entry["residual"]
    o = ap.onset(sols[2], mu_s=0.6, mu_d=0.4)
    cli_onset = json.loads(run_cli("onset", tmp_path / "out", "--load-index", 2, "--mu-s", 0.6, "--mu-d", 0.4, "--json"))
    assert o.static_coefficient == cli_onset["static_coefficient"]
    assert o.friction_drop == cli_onset["friction_drop"]
    assert o.critical.count == cli_onset["critical"]["count"]
    assert o.subcritical.friction_fraction == cli_onset["subcritical"]["friction_fraction"]
    assert o.static_force == cli_onset["static_force_n"]


def test_adhesive_contact_matches_the_command_line(tmp_path):
    t = rough_ball(grid=(64, 48))
    np.save(tmp_path / "h.npy", np.asarray(t.heights))
    lx, ly = t.physical_size
    loads = [0.0, 1e-4, -1e-6]
    adhesion = dict(adhesion_work=0.05, adhesion_range=5e-9, adhesion_law="exponential")
    run_cli("contact", tmp_path / "h.npy", "--size", f"{lx!r},{ly!r}", *(f"--load={l!r}" for l in loads),
            "--adhesion-work", "50mJ/m2", "--adhesion-range", "5nm", "--adhesion-law", "exponential",
            "--pull-off", "--out", tmp_path / "out")
    record = json.loads((tmp_path / "out" / "contact.json").read_text())
    sols = ap.contact(t, loads=loads, pull_off=True, **adhesion)
    for k, (s, entry) in enumerate(zip(sols, record["loads"])):
        assert np.array_equal(np.load(tmp_path / "out" / f"pressure-{k:03}.npy"), s.pressure)
        assert np.array_equal(np.load(tmp_path / "out" / f"traction-{k:03}.npy"), s.traction)
        assert np.array_equal(s.pressure, np.where(s.gap == 0, np.maximum(s.traction, 0.0), 0.0))
        assert (s.compressive_force, s.adhesive_force) == (entry["compressive_force_n"], entry["adhesive_force_n"])
        # N = N_c − N_a, the load asked.
        assert abs(s.compressive_force - s.adhesive_force - loads[k]) <= 1e-6 * s.compressive_force
        assert s.adhesive_force > 0 and s.pull_off == record["pull_off_n"] < loads[2]
    with pytest.raises(ap.Error, match=r"^loads?: .* below the pull-off force -[0-9.e-]+ N"):
        ap.contact(t, loads=[2 * sols[0].pull_off], **adhesion)
    with pytest.raises(ap.Error, match=r"^adhesion_work=50: 50 J/m² is not a work of adhesion .*did you mean 0.05 \(50 mJ/m²\)\?"):
        ap.contact(t, loads=[1e-4], adhesion_work=50.0, adhesion_range=5e-9)
    with pytest.raises(ap.Error, match=r"^adhesion_range=0.3: 300 mm is not the range of a cohesive law .*did you mean 3e-10 \(300 pm\)\?"):
        ap.contact(t, loads=[1e-4], adhesion_work=0.05, adhesion_range=0.3)
    with pytest.raises(ap.Error, match=r"^adhesion_work: needs adhesion_stress"):
        ap.contact(t, loads=[1e-4], adhesion_work=0.05)


def test_topography_preparation_and_psd():
    t = rough_ball(grid=128)
    tilted = ap.Topography(t.heights + 1e-3 * np.arange(128)[None, :] * t.pixel_size[0], t.physical_size)
    levelled = tilted.detrend("plane")
    assert abs(levelled.heights.mean()) < 1e-15
    # Line levelling: an offset and a tilt of each scan line (along x) of its own are removed
    # with the line's own fit, leaving the surface levelled the same way.
    rng = np.random.default_rng(3)
    x = np.arange(128)[None, :] * t.pixel_size[0]
    lines = rng.normal(0, 1e-8, (128, 1)) + rng.normal(0, 1e-3, (128, 1)) * x
    drifted = ap.Topography(t.heights + lines, t.physical_size)
    assert np.allclose(drifted.detrend("line:1").heights, t.detrend("line:1").heights, rtol=0, atol=1e-18)
    assert np.abs(drifted.detrend("line:1,plane").heights.mean(axis=1)).max() < 1e-17
    half = t.crop(x=(0, 15e-6), y=(0, 15e-6)).resample(pixel_size=0.5e-6)
    assert half.physical_size[0] == pytest.approx(half.shape[1] * 0.5e-6, rel=0.1)
    q, c = ap.psd(ap.generate(size=10e-6, grid=256, hurst=0.8, rms=1e-9, seed=2))
    assert q.dtype == c.dtype == np.float64 and q.shape == c.shape
    # C(q) ∝ q^(−2(1+H)) = q^−3.6 between the long and the short cut-off.
    band = (q > 5 * q[0]) & (q < q[-1] / 5)
    slope = np.polyfit(np.log(q[band]), np.log(c[band]), 1)[0]
    assert slope == pytest.approx(-3.6, abs=0.15)
    ball = rough_ball(grid=64)
    wafer = ap.generate(size=31.13e-6, grid=64, hurst=0.8, rms=0.2e-9, seed=9)
    h = ap.compound(ball, wafer)
    assert np.allclose(h.heights, ball.heights - wafer.heights, rtol=0, atol=1e-15)


# --- errors -----------------------------------------------------------------------------------


def raises(call, *fragments):
    with pytest.raises(ap.Error) as e:
        call()
    message = str(e.value)
    assert "\n" not in message and len(message) < 400, message
    # In Python's words: argument names, never the command line's options.
    assert not re.search(r"--[a-z]", message), message
    for f in fragments:
        assert f in message, message
    assert isinstance(e.value, ValueError)
    return message


def test_every_bad_input_raises_asperity_error(tmp_path):
    t = rough_ball(grid=32)
    (tmp_path / "bad.spm").write_bytes(b"\\*File list\r\nnot really")
    raises(lambda: ap.read_topography(tmp_path / "missing.gwy"), "missing.gwy")
    raises(lambda: ap.read_topography(tmp_path / "bad.spm"), "bad.spm")
    np.save(tmp_path / "h.npy", np.zeros((4, 4)))
    raises(lambda: ap.contact(ap.read_topography(tmp_path / "h.npy"), loads=1e-3), "h.npy", "physical size")
    raises(lambda: ap.Topography(np.zeros(5), physical_size=1e-6), "heights", "2-D")
    raises(lambda: ap.Topography([["a"]], physical_size=1e-6), "heights")
    raises(lambda: ap.Topography(np.zeros((2, 2)), physical_size=-1.0), "physical_size")
    raises(lambda: t.detrend("cubic"), "cubic")
    raises(lambda: t.crop(columns=(10, 5)))
    raises(lambda: t.crop(x=(0, 1e-6), columns=(0, 2)), "not both")
    raises(lambda: t.resample(-1.0))
    raises(lambda: ap.generate(size=1e-6, grid=8, seed=0), "nothing to generate")
    raises(lambda: ap.generate(size=1e-6, grid=8, hurst=0.8, seed=0), "rms")
    raises(lambda: ap.generate(size=1e-6, grid=8, hurst=1.5, rms=1e-9, seed=0))
    raises(lambda: ap.psd(t, window="kaiser"), "kaiser")
    raises(lambda: ap.contact(t, loads=[1e-3, -1.0]), "loads: ", "-1")
    raises(lambda: ap.contact(t, loads=[]), "loads: ")
    raises(lambda: ap.contact(t, loads=1e-3, youngs=0.0), "Young")
    raises(lambda: ap.contact(t, loads=1e-3, poisson=0.5), "Poisson")
    raises(lambda: ap.contact(t, loads=1e-3, youngs2=1e9), "youngs2/poisson2: ")
    raises(lambda: ap.contact(t, loads=1e-3, boundary="open"), "open")
    raises(lambda: ap.contact(t, loads=1e-3, tolerance=0.0), "tolerance: ")
    raises(lambda: ap.contact(t, loads=1e-3, tolerance=1e-14, max_iter=2), "did not converge", "raise max_iter")
    raises(lambda: ap.contact(t, loads=1e-3, plastic=True), "plastic: needs hardness")
    raises(lambda: ap.contact(t, loads=1e-3, hardness=-1.0), "hardness: must be positive")
    raises(lambda: ap.contact(t, loads=0.11, hardness=1e8, plastic=True), "hardness: ", "cannot carry")
    nan = np.array(t.heights)
    nan[3, 4] = np.nan
    raises(lambda: ap.contact(ap.Topography(nan, t.physical_size), loads=1e-3), "1 heights are missing")
    raises(lambda: ap.onset(np.zeros((3, 3)), mu_s=0.6, mu_d=0.4), "no contact")
    raises(lambda: ap.onset(np.array([[1.0, -2.0]]), mu_s=0.6, mu_d=0.4), "row 0, column 1")
    raises(lambda: ap.onset(np.ones((2, 2)), mu_s=0.4, mu_d=0.6), "mu")
    raises(lambda: ap.onset(np.ones((2, 2)), mu_s=0.6), "mu_s: needs mu_d too")
    raises(lambda: ap.onset(np.ones((2, 2))), "local friction law")
    raises(lambda: ap.onset(np.ones((2, 2)), law="hold 1 year"), "hold 1 year")
    raises(lambda: ap.onset(np.ones((2, 2)), mu_s=0.6, mu_d=0.4, pixel_area=0.0), "pixel_area: ")
    raises(lambda: ap.onset(np.ones((2, 2)), mu_s=0.6, mu_d=0.4).stress_ratio(2.0), "(0, 1]")
    raises(lambda: ap.onset(np.ones((2, 2)), mu_s=0.6, mu_d=0.4).curve("sideways"), "sideways")
    raises(lambda: ap.analyse_shs([0, 1, 1], [0, 0, 0], [1, 1, 1]), "time")
    raises(lambda: ap.analyse_shs(np.arange(100.0), np.ones(100), np.ones(100)), "trace")
    raises(lambda: ap.analyse_shs([0, 1], [0, 0], [1, 1], speed=-1), "speed: ")
    raises(lambda: ap.run_study({"loads": {"min": "1 mm"}}, out=tmp_path / "s"), "study dict", "loads.min")
    raises(lambda: ap.run_study(tmp_path / "none.toml", out=tmp_path / "s"), "none.toml")
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "mine.txt").write_text("a user's file")
    raises(lambda: ap.run_study(quick=True, out=tmp_path / "full"), "not empty")
    assert (tmp_path / "full" / "mine.txt").read_text() == "a user's file"


def test_the_command_lines_checks_apply(tmp_path):
    # What the command line refuses, the package refuses with the same library check.
    t = rough_ball(grid=32)
    nan = float("nan")
    raises(lambda: t.crop(x=(nan, 1e-6)), "crop: ", "x0 = NaN", "finite lengths ≥ 0")
    raises(lambda: t.crop(x=(-1e-6, 5e-6)), "crop: ", "x0 = -1e-6 m")
    raises(lambda: t.crop(y=(1e-6, float("inf"))), "crop: ", "y1 = inf")
    raises(lambda: t.crop(columns=(-1, 5)), "columns", "pixel indices ≥ 0")
    assert t.crop(x=(0.0, 10e-6)).shape == (32, 11)
    # The point limit, before anything is allocated: 2^40 points would kill the interpreter.
    raises(lambda: ap.generate(size=1e-6, grid=(2**20, 2**20), hurst=0.8, rms=1e-9, seed=0), "grid: ", "max_points")
    raises(lambda: ap.generate(size=1e-6, grid=64, hurst=0.8, rms=1e-9, seed=0, max_points=1000), "4096 points")
    raises(lambda: ap.generate(size=1e-6, grid=8, hurst=0.8, rms=1e-9, seed=0, max_points=3), "max_points")
    raises(lambda: ap.generate(size=1e-6, grid=8, hurst=0.8, rms=1e-9, seed=0, max_points=-5), "max_points", "'-5'")
    raises(lambda: ap.generate(size=1e-6, grid=8, hurst=0.8, rms=1e-9, seed=-1), "seed: ", "'-1' is not a whole")
    raises(lambda: t.resample(1e-9, max_points=10000), "pixel_size: ", "over the limit of 10000 points")
    np.save(tmp_path / "h.npy", np.zeros((64, 64)))
    raises(lambda: ap.read_topography(tmp_path / "h.npy", size=1e-6, max_points=1000), "h.npy", "1000 points")
    assert ap.read_topography(tmp_path / "h.npy", size=1e-6, max_points=4096).shape == (64, 64)
    # Every load is checked as the command line checks it: 1e120 N on 31 µm is no pressure.
    raises(lambda: ap.contact(t, loads=[1e-3, 1e120]), "loads: ", "not representable")
    # A file's content is quoted with its control characters escaped, on one line.
    (tmp_path / "t.txt").write_bytes(b"1 2\n3 4\x1b[2J\rX\n")
    message = raises(lambda: ap.read_topography(tmp_path / "t.txt"), "t.txt", "\\x1b[2J")
    assert "\x1b" not in message and "\r" not in message, message


def test_too_many_threads_are_refused_at_import():
    done = subprocess.run(
        [sys.executable, "-c", "import asperity"],
        capture_output=True,
        text=True,
        env={**os.environ, "RAYON_NUM_THREADS": "100000"},
    )
    assert done.returncode != 0
    assert "asperity.Error: RAYON_NUM_THREADS: 100000 threads is more than" in done.stderr, done.stderr


# --- slide-hold-slide and studies -------------------------------------------------------------


def test_slide_hold_slide_restarts():
    # 0.3 µm/s sliding at F_D = 0.4 N under N = 1 N, holds of 10 s and 30 s, peaks 0.5 and 0.55 N.
    dt, v = 0.05, 0.3e-6
    t, f = [], []
    clock = 0.0

    def slide(duration, peak):
        nonlocal clock
        for i in range(int(duration / dt)):
            x = i * dt * v
            f.append(0.4 + (peak - 0.4) * math.exp(-x / 0.02e-6) if peak else 0.4)
            t.append(clock)
            clock += dt

    def hold(duration):
        nonlocal clock
        for _ in range(int(duration / dt)):
            f.append(0.0)
            t.append(clock)
            clock += dt

    slide(20, None)
    hold(10)
    slide(20, 0.5)
    hold(30)
    slide(20, 0.55)
    cycles = ap.analyse_shs(np.array(t), np.array(f), np.ones(len(t)))
    assert [round(c["hold_s"]) for c in cycles] == [10, 30]
    assert cycles[0]["static_force_n"] == pytest.approx(0.5, rel=1e-9)
    assert cycles[1]["friction_drop"] == pytest.approx(0.55 / cycles[1]["dynamic_force_n"], rel=1e-12)
    assert cycles[1]["dynamic_coefficient"] == pytest.approx(0.4, rel=0.02)
    # A window starting 0.5 µm past the peak leaves out the fall from F_S: F_D is the sliding level.
    later = ap.analyse_shs(np.array(t), np.array(f), np.ones(len(t)), window_start=0.5e-6)
    assert later[1]["window_start_s"] > later[1]["peak_s"] == cycles[1]["window_start_s"]
    assert later[1]["dynamic_force_n"] == pytest.approx(0.4, rel=1e-6)


SMALL_STUDY = {
    "topography": [
        {"name": "ball", "synthetic": {"size_m": [10e-6, 10e-6], "grid": [48, 48], "seed": 3,
                                       "roughness": {"hurst": 0.8, "rms_height_m": 5e-9},
                                       "cap": {"radius_m": 1e-3, "shape": "sphere"}}},
    ],
    "loads": {"values": ["0.1 mN", "1 mN"]},
    "law": [{"name": "a", "mu_s": 0.6, "mu_d": 0.4}],
    "output": {"figures": []},
}


def test_a_study_from_a_dict_runs_and_resumes(tmp_path):
    events = []
    rows = ap.run_study(SMALL_STUDY, out=tmp_path / "r", progress=events.append)
    assert [r["load_n"] for r in rows] == [1e-4, 1e-3]
    # A solve's work: its grid points times 1 + the decades its load lies above the lowest.
    assert events[0] == {"event": "start", "total": 2, "done": 0, "work": 3 * 48 * 48,
                         "work_done": 0, "onsets": 0, "onsets_done": 0}
    assert [e["event"] for e in events[1:]] == ["solved", "solved"]
    assert [e["work"] for e in events[1:]] == [48 * 48, 2 * 48 * 48]
    # The rows are the direct calls' numbers (the default study's tolerance is 1e-8).
    t = ap.generate(size=10e-6, grid=48, hurst=0.8, rms=5e-9, sphere_radius=1e-3, seed=3)
    sols = ap.contact(t, loads=[1e-4, 1e-3], tolerance=1e-8)
    for r, s in zip(rows, sols):
        o = ap.onset(s, mu_s=0.6, mu_d=0.4)
        assert (r["contact_points"], r["patches"], r["iterations"]) == (s.contact_points, s.patches, s.iterations)
        assert (r["friction_drop"], r["static_coefficient"]) == (o.friction_drop, o.static_coefficient)
    on_file = json.loads((tmp_path / "r" / "results.json").read_text())
    assert on_file["rows"] == rows
    assert on_file["asperity_version"] == ap.__version__
    again = ap.run_study(SMALL_STUDY, out=tmp_path / "r")
    assert [{k: v for k, v in r.items() if k != "seconds"} for r in again] == \
        [{k: v for k, v in r.items() if k != "seconds"} for r in rows]


def test_a_study_with_elastic_sharing_counts_its_onsets(tmp_path):
    events = []
    study = dict(SMALL_STUDY, model={"sharing": ["equal", "elastic"]})
    rows = ap.run_study(study, out=tmp_path / "r", progress=events.append)
    assert events[0] == {"event": "start", "total": 2, "done": 0, "work": 3 * 48 * 48,
                         "work_done": 0, "onsets": 2, "onsets_done": 0}
    # Each load's onset is reported before its solve (these onsets take less than the second
    # after which one under way reports).
    assert [e["event"] for e in events[1:]] == ["slid", "solved", "slid", "solved"]
    assert [r["sharing"] for r in rows].count("elastic") == 2


def test_a_study_stops_when_its_progress_callback_raises(tmp_path):
    class Stop(Exception):
        pass

    def stop(event):
        if event["event"] == "solved":
            raise Stop()

    with pytest.raises(Stop):
        ap.run_study(SMALL_STUDY, out=tmp_path / "r", progress=stop)
    # What was solved is kept; the run resumes to the full results.
    events = []
    rows = ap.run_study(SMALL_STUDY, out=tmp_path / "r", progress=events.append)
    assert events[0]["event"] == "start" and events[0]["done"] >= 1
    # No pressure map left to go on from once every solve is recorded.
    assert len(rows) == 2 and not list((tmp_path / "r" / "solves").rglob("*-warm.npy"))


# --- the GIL and Ctrl-C -----------------------------------------------------------------------


def test_solves_release_the_gil():
    """Two solves in two threads overlap in time; with the GIL held they would run one after
    the other. The overlap is measured on the solves' own intervals, not against a clock."""
    t = rough_ball(grid=256)
    spans = {}

    def solve(name):
        start = time.perf_counter()
        ap.contact(t, loads=[1e-3, 3e-3, 1e-2])
        spans[name] = (start, time.perf_counter())

    threads = [threading.Thread(target=solve, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    # The main thread keeps running Python meanwhile: it could not with the GIL held.
    ticks = 0
    while any(th.is_alive() for th in threads):
        ticks += 1
        time.sleep(0.001)
    for th in threads:
        th.join()
    (a0, a1), (b0, b1) = spans[0], spans[1]
    overlap = min(a1, b1) - max(a0, b0)
    shorter = min(a1 - a0, b1 - b0)
    assert overlap > 0.5 * shorter, (spans, overlap)
    assert ticks > 10


def seconds_to_stop(setup, call):
    """Seconds from Ctrl-C to the end of a child Python that runs `setup` (after `import
    asperity as ap`), then the long `call`, SIGINT coming 1 s into it; the child must have
    raised KeyboardInterrupt from `call`."""
    script = textwrap.dedent("""
        import signal, sys
        import asperity as ap
        # Python's own handler, also where the test runs with SIGINT ignored (a background job).
        signal.signal(signal.SIGINT, signal.default_int_handler)
        {setup}
        print("calling", flush=True)
        try:
            {call}
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(0)
        sys.exit("not interrupted")
    """).format(setup=setup, call=call)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "calling"
    time.sleep(1.0)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert child.returncode == 0, out
    assert "interrupted" in out
    return time.perf_counter() - sent


def test_ctrl_c_stops_a_long_solve():
    # A solve that cannot converge (tolerance 1e-300) would run 20000 iterations (minutes):
    # stopped within a few iterations of the signal.
    setup = "t = ap.generate(size=31.13e-6, grid=512, hurst=0.8, rms=22e-9, rolloff=5e-6, sphere_radius=1.5e-3, seed=1)"
    assert seconds_to_stop(setup, "ap.contact(t, loads=1e-2, tolerance=1e-300)") < 30


def test_ctrl_c_stops_a_long_slide():
    # The path to sliding at 512², 100 mN with d_c = 2 nm took 24 s on 2 cores (hundreds of
    # steps, a study beside it); Ctrl-C stops it at its next step.
    setup = ("t = ap.generate(size=31.13e-6, grid=512, hurst=0.8, rms=21e-9, rolloff=7e-6, cutoff=0.25e-6, "
             "sphere_radius=1.5e-3, seed=1); (s,) = ap.contact(t, loads=0.1)")
    assert seconds_to_stop(setup, "ap.slide(s, mu_s=0.6, mu_d=0.4, slip_distance=2e-9)") < 5


# --- plausibility, warnings, hardness, elastic sharing (the command line's, in Python) -----------


def test_implausible_values_are_refused_with_the_unit_meant():
    t = rough_ball(grid=32)
    message = raises(lambda: ap.contact(t, loads=1e-3, youngs=130), "youngs=130: 130 Pa is not a solid's Young's modulus")
    assert message.endswith("did you mean 1.3e11 (130 GPa)?"), message
    raises(lambda: ap.contact(t, loads=1e-3, hardness=12), "hardness=12: ", "did you mean 1.2e10 (12 GPa)?")
    raises(lambda: ap.contact(t, loads=1e3), "loads=1000: ", "no contact of this kind is pressed that hard")
    raises(lambda: ap.generate(size=31.13, grid=8, seed=0, sphere_radius=1e3), "size=31.13: ", "3.113e-5 (31.13 µm)?")
    raises(lambda: ap.Topography(np.zeros((2, 2)), physical_size=31.13), "physical_size=31.13: ")
    raises(lambda: ap.onset(np.ones((2, 2)), mu_s=60, mu_d=40), "mu_s=60: a friction coefficient of 60 is above 10")
    raises(lambda: t.resample(20.0), "pixel_size=20: ", "did you mean 2e-8 (20 nm)?")
    raises(lambda: t.add_cap(1.5e4), "radius=15000: ")


def test_a_heavy_load_warns_through_the_warnings_module():
    # 1 N on 31 µm of silicon (1 mN meant) is 7e-3 E*: the command line warns, so does Python.
    t = rough_ball(grid=32)
    with pytest.warns(UserWarning) as caught:
        (s,) = ap.contact(t, loads=1.0)
    said = [str(w.message) for w in caught]
    assert said[0].startswith("loads=1: 1 N on the 31.13 µm × 31.13 µm window is a mean pressure of"), said
    assert said[0].endswith("did you mean 0.001 (1 mN)?"), said
    assert all(w.filename == __file__ for w in caught), [w.filename for w in caught]
    assert s.warnings == said
    # A contact cut by the window names Python's remedies.
    assert any("of the load sits within 2 % of the window's edges" in w and 'boundary="free"' in w for w in said), said
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning):
            ap.contact(t, loads=1.0)
        (quiet,) = ap.contact(t, loads=1e-4)  # the default range: nothing to say
    assert quiet.warnings == []


def test_hardness_and_plastic_match_the_command_line(tmp_path):
    t = rough_ball(grid=(64, 48))
    np.save(tmp_path / "h.npy", np.asarray(t.heights))
    lx, ly = t.physical_size
    loads = [1e-2, 1e-3]
    run_cli("contact", tmp_path / "h.npy", "--size", f"{lx!r},{ly!r}", *(f"--load={l!r}" for l in loads),
            "--hardness", "0.3GPa", "--plastic", "--fields", "--out", tmp_path / "out")
    record = json.loads((tmp_path / "out" / "contact.json").read_text())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sols = ap.contact(t, loads=loads, hardness=0.3e9, plastic=True)
    assert len(caught) == len(record["warnings"]) and len(caught) > 0, (record["warnings"], caught)
    for k, (s, entry) in enumerate(zip(sols, record["loads"])):
        assert np.array_equal(np.load(tmp_path / "out" / f"pressure-{k:03}.npy"), s.pressure)
        assert np.array_equal(np.load(tmp_path / "out" / f"displacement-{k:03}.npy"), s.displacement)
        assert s.max_pressure == entry["max_pressure_pa"] <= 0.3e9
        assert s.edge_load_fraction == entry["edge_load_fraction"]
        assert s.load_above_hardness_fraction == entry["load_above_hardness_fraction"]
        assert s.operator_applications == entry["operator_applications"]
        assert (s.hardness, s.plastic, s.effective_modulus) == (0.3e9, True, record["effective_modulus_pa"])
    assert sols[0].load_above_hardness_fraction > 0  # 10 mN on this ball reaches 0.3 GPa
    # The warnings of a load name it as the command line does.
    assert any(w.startswith("at 10 mN: ") for w in sols[0].warnings), sols[0].warnings


def test_slide_matches_the_command_line(tmp_path):
    t = rough_ball(grid=48)
    np.save(tmp_path / "h.npy", np.asarray(t.heights))
    lx, ly = t.physical_size
    run_cli("contact", tmp_path / "h.npy", "--size", f"{lx!r},{ly!r}", "--load", "1e-3", "--out", tmp_path / "c")
    run_cli("slide", tmp_path / "c", "--mu-s", 0.6, "--mu-d", 0.4, "--out", tmp_path / "s")
    record = json.loads((tmp_path / "s" / "slide.json").read_text())
    (s,) = ap.contact(t, loads=1e-3)
    sl = ap.slide(s, mu_s=0.6, mu_d=0.4)
    assert sl.static_coefficient == record["static_coefficient"]
    assert sl.friction_drop == record["friction_drop"]
    assert sl.static_force == record["static_force_n"]
    assert sl.peak_displacement == record["peak_displacement_m"]
    assert sl.equal_sharing_friction_drop == record["equal_sharing"]["friction_drop"]
    assert sl.equal_sharing_friction_drop == ap.onset(s, mu_s=0.6, mu_d=0.4).friction_drop
    classes = ("stuck", "critical", "weakening", "weakened")
    assert [getattr(sl, c).count for c in classes] == [record[c]["count"] for c in classes]
    assert sum(getattr(sl, c).count for c in classes) == sl.contact_points
    assert np.array_equal(np.load(tmp_path / "s" / "shear_x.npy"), sl.shear_x)
    assert np.array_equal(np.load(tmp_path / "s" / "classes.npy"), sl.classes)
    curve = np.loadtxt(tmp_path / "s" / "curve.csv", delimiter=",", skiprows=1)
    # curve() as curve.csv, its columns named alike (displacement_m, force_n, …).
    path = sl.curve()
    names = (tmp_path / "s" / "curve.csv").read_text().splitlines()[0].split(",")
    assert names == ["displacement_m", "force_n", "stick_points", "slip_points"]
    for k, name in enumerate(names):
        assert np.array_equal(curve[:, k], path[name]), name
    # The march's states, solved to its looser tolerance, may lie above F_S by about 1e-4 of it.
    assert sl.static_force <= path["force_n"].max() <= sl.static_force * (1 + 1e-4)
    # One default for one physics: the study's d_c, and equal sharing with the same weakening.
    assert sl.slip_distance == 2e-9 == record["law"]["slip_distance_m"]
    same = record["equal_sharing_same_law"]
    assert sl.equal_sharing_same_law_friction_drop == same["friction_drop"]
    assert sl.equal_sharing_same_law_static_coefficient == same["static_coefficient"]
    # The partial-slip state at an imposed force, as --tangential-force.
    q = 0.5 * 0.6 * s.load
    run_cli("slide", tmp_path / "c", "--mu-s", 0.6, "--mu-d", 0.4, "--tangential-force", repr(q), "--out", tmp_path / "q")
    ramp = json.loads((tmp_path / "q" / "slide.json").read_text())
    partial = ap.slide(s, mu_s=0.6, mu_d=0.4, tangential_force=q)
    assert (partial.tangential_force, partial.displacement) == (ramp["tangential_force_n"], ramp["displacement_m"])
    assert (partial.stick_points, partial.slip_points) == (ramp["stick_points"], ramp["slip_points"])
    raises(lambda: ap.slide(s, mu_s=0.6, mu_d=0.4, tangential_force=s.load), "tangential_force: must lie in")
    raises(lambda: ap.slide(s, mu_s=0.6, mu_d=0.4, slip_distance=-1.0), "slip_distance: ")
    raises(lambda: ap.slide(s, mu_s=0.6), "mu_s: needs mu_d too")


def test_a_scan_solved_with_a_hardness_slides_and_plots(tmp_path):
    # The notebook a user writes: read a scan, level it, add the ball's curvature, solve with a
    # hardness, slide with elastic sharing, plot (when matplotlib is there: `pip install .[plot]`).
    scan = ap.read_topography(ROOT / "tests" / "data" / "si-ball-roughness.gwy")
    assert scan.height_unit == "m" and scan.shape == (200, 160)
    ball = scan.detrend("plane").add_cap(1.5e-3)
    assert not ball.periodic
    (s,) = ap.contact(ball, loads=1e-4, hardness=12e9, plastic=True)
    assert s.max_pressure <= 12e9 and s.contact_points > 10 and s.warnings == []
    sl = ap.slide(s, mu_s=0.6, mu_d=0.4)
    assert 1.0 < sl.friction_drop < 0.6 / 0.4
    assert sl.classes[s.pressure == 0].max() == 0 and sl.classes.max() > 0
    try:
        import matplotlib
    except ImportError:
        return
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2)
    a.imshow(s.pressure / 1e9)
    path = sl.curve()
    b.plot(path["displacement_m"] * 1e9, path["coefficient"])
    fig.savefig(tmp_path / "slide.png")
    plt.close(fig)
    assert (tmp_path / "slide.png").stat().st_size > 0


def test_signatures_show_their_defaults_and_the_stub_matches():
    assert inspect.signature(ap.contact).parameters["youngs"].default == 130e9
    assert inspect.signature(ap.contact).parameters["tolerance"].default == 1e-10
    assert inspect.signature(ap.slide).parameters["max_iter"].default == 20000
    stub = ast.parse((Path(ap.__file__).parent / "_asperity.pyi").read_text())
    from asperity import _asperity

    for node in stub.body:
        if isinstance(node, ast.FunctionDef):  # the overloads of slide have its parameters
            function = getattr(_asperity, node.name)
            stubbed = [a.arg for a in node.args.posonlyargs + node.args.args + node.args.kwonlyargs]
            assert stubbed == list(inspect.signature(function).parameters), node.name
        elif isinstance(node, ast.ClassDef):
            cls = getattr(_asperity, node.name)
            for member in node.body:
                name = getattr(member, "name", None) or getattr(getattr(member, "target", None), "id", None)
                if name and not name.startswith("__"):
                    assert hasattr(cls, name), f"{node.name}.{name}"
    public = {n for n in dir(_asperity) if not n.startswith("__")}
    stubbed = {getattr(n, "name", None) for n in stub.body} | {
        t.id for n in stub.body if isinstance(n, ast.AnnAssign) for t in [n.target]
    }
    assert public <= stubbed, public - stubbed


def test_statistics_are_surface_topographys():
    # SurfaceTopography 1.27.1 on the same file: rms_gradient, rms_curvature_from_area.
    t = ap.read_topography(ROOT / "tests" / "data" / "si-ball-roughness.gwy")
    s = t.statistics()
    assert s["rms_height"] == pytest.approx(1.2078773492359754e-08, rel=1e-9)
    assert s["rms_gradient"] == pytest.approx(0.06727190036769483, rel=1e-9)
    assert s["rms_slope_from_profile"] == pytest.approx(0.0482823519044096, rel=1e-9)
    assert s["rms_curvature_from_area"] == pytest.approx(304481.4766922735, rel=1e-9)
    assert s["rms_curvature_from_profile"] == pytest.approx(378573.9694702846, rel=1e-9)


# --- measured friction curves and line profiles ---------------------------------------------------

AFM_CURVE = "x_nm,mu\n0,0.1\n10,0.7\n20,0.5\n30,0.4\n40,0.42\n"


def test_a_curve_law_is_the_command_lines(tmp_path):
    # The curve peaks at 0.7; over 5…25 nm past the peak (20, 30 nm) mu_d = 0.45, after it all 0.44.
    (tmp_path / "afm.csv").write_text(AFM_CURVE)
    p = np.array([[0.0, 2e8, 0.0], [5e7, 0.0, 1e8], [0.0, 3e8, 0.0]])
    np.save(tmp_path / "p.npy", p)
    record = json.loads(run_cli("onset", tmp_path / "p.npy", "--curve", tmp_path / "afm.csv", "--window", "5,25",
                                "--json"))
    o = ap.onset(p, mu_s=None, curve=tmp_path / "afm.csv", window=(5, 25))
    assert (o.mu_s, o.mu_d) == (0.7, pytest.approx(0.45, rel=1e-15))
    assert (record["law"]["mu_s"], record["law"]["mu_d"]) == (o.mu_s, o.mu_d)
    assert o.static_coefficient == record["static_coefficient"]
    assert o.friction_drop == record["friction_drop"]
    assert ap.onset(p, curve=str(tmp_path / "afm.csv")).mu_d == pytest.approx((0.5 + 0.4 + 0.42) / 3, rel=1e-15)
    # Errors in Python's words.
    raises(lambda: ap.onset(p, curve=tmp_path / "afm.csv", window=(25, 5)), "window: ")
    raises(lambda: ap.onset(p, mu_s=0.6, mu_d=0.4, curve=tmp_path / "afm.csv"), "curve: give mu_s and mu_d")
    raises(lambda: ap.onset(p, mu_s=0.6, mu_d=0.4, window=(5, 25)), "window: applies to a curve only")


def test_slide_follows_a_curve_as_the_command_line(tmp_path):
    (tmp_path / "afm.csv").write_text(AFM_CURVE)
    t = rough_ball(grid=32)
    np.save(tmp_path / "h.npy", np.asarray(t.heights))
    lx, ly = t.physical_size
    run_cli("contact", tmp_path / "h.npy", "--size", f"{lx!r},{ly!r}", "--load", "1e-3", "--out", tmp_path / "c")
    run_cli("slide", tmp_path / "c", "--curve", tmp_path / "afm.csv", "--curve-unit", "1nm", "--out", tmp_path / "s")
    record = json.loads((tmp_path / "s" / "slide.json").read_text())
    (s,) = ap.contact(t, loads=1e-3)
    sl = ap.slide(s, curve=tmp_path / "afm.csv", curve_unit=1e-9)
    assert sl.mu_s == 0.7
    assert sl.static_coefficient == record["static_coefficient"]
    assert sl.friction_drop == record["friction_drop"]
    raises(lambda: ap.slide(s, curve=tmp_path / "afm.csv"), "curve_unit: a curve needs its displacement unit")
    raises(lambda: ap.slide(s, curve=tmp_path / "afm.csv", curve_unit=1e-9, slip_distance=1e-9), "slip_distance: ")


def test_a_line_profile_reads_as_one_with_surface_topographys_statistics():
    # dektak-1.csv on the grid its header states (tests/data/manifest.json: numpy's values), in µm.
    dektak = ROOT / "tests" / "data" / "dektak-1.csv"
    p = ap.read_topography(dektak)
    assert isinstance(p, ap.Profile) and p.points == 9600
    assert p.step == pytest.approx(1499.8e-6 / 9599, rel=1e-12)
    assert p.length == pytest.approx(9600 * 1499.8e-6 / 9599, rel=1e-12)
    s = p.statistics()
    assert s["mean"] == pytest.approx(8.455879258333335e-6, rel=1e-9)
    assert s["rms_height"] == pytest.approx(4.764232930211046e-6, rel=1e-9)
    assert s["rms_slope"] == pytest.approx(0.01455489680150049, rel=1e-9)
    info = json.loads(run_cli("topo", "info", dektak, "--json"))
    assert (s["rms_height"], s["rms_curvature"]) == (info["rms_m"], info["rms_curvature_per_m"])
    # Levelled as topo info --detrend levels it: numpy's polyfit residual of degree 1.
    line = p.detrend("line:1")
    assert line.statistics()["rms_height"] == pytest.approx(9.424304890540356e-08, rel=1e-9)
    info = json.loads(run_cli("topo", "info", dektak, "--json", "--detrend", "line:1"))
    assert line.statistics()["rms_height"] == info["rms_m"]
    assert p.detrend().statistics()["rms_height"] == info["rms_m"]
    raises(lambda: p.detrend("sphere"), "kind: ", "a line profile is levelled by")
    # What needs a map says which functions take a profile.
    raises(lambda: ap.contact(p, loads=1e-3), "topography: a line profile", "psd()")
    with pytest.raises(TypeError, match="expected a Topography"):
        ap.contact("scan.gwy", loads=1e-3)
    raises(lambda: ap.psd(ap.read_topography(ROOT / "tests" / "data" / "xy-1.txt", height_unit="um")), "not uniform")
    # Heights in nm handed over as metres: the unit is named, not the advice for generate().
    rough = ap.Topography(np.random.default_rng(0).normal(scale=20.0, size=(32, 32)), (1e-6, 1e-6))
    raises(lambda: ap.contact(rough, loads=1e-3), "not heights in metres", "give their unit, e.g. nm")
    # Without units: refused in Python's words, then given.
    xy = ROOT / "tests" / "data" / "xy-1.txt"
    raises(lambda: ap.read_topography(xy).statistics(), "height_unit")
    s = ap.read_topography(xy, height_unit="um").statistics()
    # The positions' unit of their own: in mm, the profile is 1000 times as long.
    mm = ap.read_topography(xy, height_unit="um", position_unit="mm")
    assert mm.length == pytest.approx(1000 * ap.read_topography(xy, height_unit="um").length, rel=1e-12)
    raises(lambda: ap.read_topography(dektak, position_unit="mm"), "position_unit: ", "states the unit of its positions")
    assert s["rms_height"] == pytest.approx(3.0585577255814207e-6, rel=1e-9)
    assert s["rms_slope"] == pytest.approx(0.4382415170673911, rel=1e-9)


def test_the_spectrum_of_a_uniform_profile_is_topo_psds(tmp_path):
    x = np.arange(64) * 0.5e-6
    h = 1e-8 * np.sin(2 * np.pi * 5 * np.arange(64) / 64)
    np.savetxt(tmp_path / "p.csv", np.column_stack([x * 1e6, h * 1e6]), delimiter=",", header="x_um,h_um", comments="")
    p = ap.read_topography(tmp_path / "p.csv")  # the header states µm
    assert isinstance(p, ap.Profile) and p.height_unit is not None and p.step == pytest.approx(0.5e-6, rel=1e-12)
    q, c = ap.psd(p)
    assert q[np.argmax(c)] == pytest.approx(2 * np.pi * 5 / 32e-6, rel=1e-12)
    cli_q, cli_c = np.loadtxt(io.StringIO(run_cli("topo", "psd", tmp_path / "p.csv")),
                              delimiter=",", skiprows=1, unpack=True)
    assert np.allclose(q, cli_q, rtol=1e-15) and np.allclose(c, cli_c, rtol=1e-15)


def test_an_empty_out_is_refused_and_the_working_folder_kept(tmp_path, monkeypatch):
    # out="" named no folder and wrote the study among the user's files in the working folder.
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results.csv").write_text("a user's table")
    message = raises(lambda: ap.run_study(SMALL_STUDY, out=""), "out: an empty path names no folder")
    assert message == "out: an empty path names no folder: choose a new or empty folder"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.csv"]
    assert (tmp_path / "results.csv").read_text() == "a user's table"


def in_a_python(code, memory_bytes=None):
    """`code` run by a Python of its own (asperity imported as ap, numpy as np), its address
    space limited to what it maps then plus `memory_bytes`: an abort fails the test, not pytest."""
    limit = "" if memory_bytes is None else textwrap.dedent(f"""
        import resource
        mapped = next(int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmSize:"))
        resource.setrlimit(resource.RLIMIT_AS, (mapped + {memory_bytes}, resource.RLIM_INFINITY))
    """)
    script = "import numpy as np\nimport asperity as ap\n" + limit + textwrap.dedent(code)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, (done.returncode, done.stderr)
    return done.stdout.strip()


def test_a_map_beyond_the_point_limit_or_the_memory_is_refused_before_its_copy():
    # A read-only broadcast of 2^30 points was copied whole: the interpreter aborted.
    said = in_a_python("""
        try:
            ap.Topography(np.broadcast_to(0.0, (2**15, 2**15)), 1e-3)
        except ValueError as e:
            print(e)
    """)
    assert said == ("heights: a 32768 × 32768 grid (1073741824 points) is over the limit of 268435456 points "
                    "(raise it with max_points, or max_points in the study's [limits])"), said
    # One row past 2^28 passed the limit.
    raises(lambda: ap.Topography(np.broadcast_to(0.0, (16385, 16384)), 1e-3),
           "heights: a 16384 × 16385 grid (268451840 points) is over the limit of 268435456 points")
    raises(lambda: ap.Topography(np.zeros((4, 5)), 1e-6, max_points=19), "20 points) is over the limit of 19")
    assert ap.Topography(np.zeros((4, 5)), 1e-6, max_points=20).shape == (4, 5)
    # Within a raised limit, a copy the memory cannot hold is a MemoryError, estimated before it.
    said = in_a_python("""
        try:
            ap.Topography(np.broadcast_to(0.0, (2**15, 2**15)), 1e-3, max_points=2**30)
        except MemoryError as e:
            print(type(e).__name__, e)
    """, memory_bytes=256 << 20)
    assert said.startswith("MemoryError heights: a 32768 × 32768 map of heights needs about 16.0 GiB of memory, "
                           "more than the "), said


def test_heights_the_readers_refuse_are_refused_and_missing_points_stay_missing():
    # Infinite and 1e308 heights were taken: no missing point, NaN or infinite statistics.
    for bad, shown in [(np.inf, "inf"), (-np.inf, "-inf"), (1e308, "1e308")]:
        h = np.zeros((8, 8))
        h[2, 3] = bad
        raises(lambda: ap.Topography(h, 1e-6),
               f"heights: the value at row 2, column 3 is {shown}, beyond ±1e50 (m): not representable")
    # A wafer's missing point makes the compound's heights within two pixels of it missing,
    # counted as such and refused where heights are needed, never taken as heights.
    ball = rough_ball(grid=32)
    wafer = np.zeros((32, 32))
    wafer[10, 12] = np.nan
    c = ap.compound(ball, ap.Topography(wafer, ball.physical_size))
    assert c.missing_points == 16 and np.isnan(c.heights).sum() == 16
    assert np.isnan(c.heights[8:12, 10:14]).all() and np.isfinite(np.delete(c.heights, range(8, 12), 0)).all()
    raises(lambda: c.statistics(), "missing")
    raises(lambda: ap.contact(c, loads=1e-3), "16 heights are missing")
    assert c.fill_missing().missing_points == 0


def test_a_youngs_uncertainty_outside_zero_to_youngs_is_refused(tmp_path):
    # An uncertainty of E or more drew the study's E band through E <= 0.
    for delta, shown in [("130 GPa", "130 GPa"), ("-1 GPa", "-1 GPa")]:
        study = dict(SMALL_STUDY, material={"youngs": "130 GPa", "youngs_uncertainty": delta})
        raises(lambda: ap.run_study(study, out=tmp_path / "r"),
               f"material.youngs_uncertainty: {shown} must lie in [0, youngs) = [0, 130 GPa)")
    assert not (tmp_path / "r").exists()


def test_a_slide_beyond_the_memory_is_a_memory_error():
    # The tangential solve's buffers were allocated unchecked: short of memory, the interpreter
    # aborted. Its estimate is checked first.
    said = in_a_python("""
        import resource
        t = ap.generate(size=31.13e-6, grid=512, hurst=0.8, rms=22e-9, seed=1)
        (s,) = ap.contact(t, loads=1e-3, tolerance=1e-6)
        mapped = next(int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmSize:"))
        resource.setrlimit(resource.RLIMIT_AS, (mapped + (16 << 20), resource.RLIM_INFINITY))
        try:
            ap.slide(s, law="hold 100 s")
        except MemoryError as e:
            print(type(e).__name__, e)
    """)
    assert said.startswith("MemoryError surface: a tangential solve on 512 × 512 points needs about 97 MiB of "
                           "memory, more than the "), said
