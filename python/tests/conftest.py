"""What the Python tests share: the command line they compare the package with."""

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli():
    """The asperity binary, or skip when this checkout has none and none was named."""
    named = os.environ.get("ASPERITY_CLI")
    if named:
        assert Path(named).is_file(), f"ASPERITY_CLI={named} does not exist"
        return named
    built = ROOT / "target" / "release" / "asperity"
    if not built.is_file():
        pytest.skip("no asperity binary: run `cargo build --release` or set ASPERITY_CLI")
    return str(built)
