"""The example notebook runs as shipped: its code cells, in order, in one namespace, from the
notebook's folder (as `jupyter nbconvert --execute` runs it). A cell tagged `needs-matplotlib`
runs only where matplotlib is installed (`pip install .[plot]`)."""

import json
from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parents[2] / "examples" / "scan-to-friction.ipynb"


def test_the_example_notebook_runs(monkeypatch, tmp_path):
    cells = [c for c in json.loads(NOTEBOOK.read_text())["cells"] if c["cell_type"] == "code"]
    assert len(cells) >= 4
    try:
        import matplotlib  # noqa: F401

        plotting = True
    except ImportError:
        plotting = False
    monkeypatch.chdir(NOTEBOOK.parent)
    namespace = {"__name__": "__main__"}
    for i, cell in enumerate(cells):
        if "needs-matplotlib" in cell["metadata"].get("tags", []) and not plotting:
            continue
        source = "".join(cell["source"])
        if plotting:
            # The figure goes to the test's folder, not into the repository.
            source = source.replace('"scan-to-friction.png"', repr(str(tmp_path / "scan-to-friction.png")))
        exec(compile(source, f"{NOTEBOOK.name}, code cell {i}", "exec"), namespace)
    slide = namespace["slide"]
    assert 1.0 < slide.friction_drop < 0.6 / 0.4
    assert slide.slip_distance == pytest.approx(2e-9)
    if plotting:
        assert (tmp_path / "scan-to-friction.png").stat().st_size > 10_000
