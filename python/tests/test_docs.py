"""The package documents itself: every public name has a docstring, and ``help(asperity.contact)``
states each parameter's unit and default as the code has them.

The comparison with the command line runs the `asperity` binary: $ASPERITY_CLI, or
target/release/asperity of this checkout (skipped when neither exists).
"""

import inspect
import re
import subprocess

import numpy as np
import pytest

import asperity as ap
from conftest import cli

# Data, not callables: the package's docstring describes them.
DATA = {"PRESETS", "__version__"}


def undocumented(name, obj):
    """`name` and each public member of a class `obj` whose own docstring is empty."""
    missing = [] if (obj.__doc__ or "").strip() else [name]
    if inspect.isclass(obj):
        for attr, member in vars(obj).items():
            if not attr.startswith("_") and not (getattr(member, "__doc__", None) or "").strip():
                missing.append(f"{name}.{attr}")
    return missing


def test_every_public_name_has_a_docstring():
    assert set(ap.__all__) - DATA, "nothing to check"
    missing = [m for name in sorted(set(ap.__all__) - DATA) for m in undocumented(name, getattr(ap, name))]
    assert not missing, f"no docstring: {missing}"
    for name in DATA:
        assert f"``{name}``" in ap.__doc__, name


def test_the_check_sees_a_missing_docstring():
    class Bare:
        def method(self):
            pass

        @property
        def value(self):
            return 1

    assert undocumented("Bare", Bare) == ["Bare", "Bare.method", "Bare.value"]


def words(text):
    """`text` with every run of white space one space, as help() reads across its lines."""
    return " ".join(text.split())


def test_contact_states_every_parameter_with_its_unit():
    doc = words(ap.contact.__doc__)
    for name in inspect.signature(ap.contact).parameters:
        assert re.search(rf"``{name}(``|=)", doc), name
    for name, unit in [("loads", "N"), ("youngs", "Pa"), ("youngs2", "Pa"), ("hardness", "Pa")]:
        assert f"``{name}`` [{unit}]" in doc, name
    assert re.search(r"``topography``[^.]*heights \[m\][^.]*physical size \[m\]", doc)


def test_contact_states_its_defaults_as_the_code_has_them():
    doc = words(ap.contact.__doc__)
    defaults = {n: p.default for n, p in inspect.signature(ap.contact).parameters.items()}
    silicon = re.search(r"default silicon: ([0-9.e+-]+) Pa and ([0-9.]+)\)", doc)
    assert silicon and (float(silicon[1]), float(silicon[2])) == (defaults["youngs"], defaults["poisson"])
    for name in ["tolerance", "max_iter"]:
        stated = re.search(rf"``{name}`` \(default ([0-9.e+-]+)\)", doc)
        assert stated and float(stated[1]) == defaults[name], name
    for name in ["youngs2", "poisson2", "hardness"]:
        assert re.search(rf"``{name}``[^;]*\(default None", doc) and defaults[name] is None, name
    assert "``plastic=True`` (default False)" in doc and defaults["plastic"] is False
    assert f'"{defaults["boundary"]}" (default)' in doc
    assert f'"{defaults["device"]}" (default' in doc


def test_the_stated_tolerance_is_the_solvers_default():
    # The signature's value is text; the default the solver takes is Rust's. Solved with the
    # stated value the solve is the default's to the last iteration; a looser one is not.
    t = ap.generate(size=31.13e-6, grid=64, hurst=0.8, rms=22e-9, rolloff=5e-6, sphere_radius=1.5e-3, seed=1)
    stated = inspect.signature(ap.contact).parameters["tolerance"].default
    default, explicit, looser = (
        ap.contact(t, 1e-3, **kw)[0] for kw in [{}, {"tolerance": stated}, {"tolerance": stated * 100}]
    )
    assert (default.iterations, default.residual) == (explicit.iterations, explicit.residual)
    assert np.array_equal(default.pressure, explicit.pressure)
    assert looser.iterations < default.iterations


def test_contact_defaults_are_the_command_lines():
    done = subprocess.run([cli(), "contact", "--help"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    defaults = {n: p.default for n, p in inspect.signature(ap.contact).parameters.items()}
    for option, name in [("--tolerance", "tolerance"), ("--max-iter", "max_iter")]:
        stated = re.search(rf"{option} <\w+>\n.*?\[default: ([^\]]+)\]", done.stdout, re.S)
        assert stated and float(stated[1]) == defaults[name], option
