"""asperity: the static friction coefficient of rough interfaces from their measured topography.

After Peng, Roch, Bonn & Weber, Phys. Rev. Lett. 134, 176202 (2025). The whole pipeline of the
``asperity`` command line, from Python: read or generate a topography, solve the elastic
contact, run the stick-slip transition model, analyse slide-hold-slide traces, run a study.

Units are SI everywhere (m, Pa, N); maps are numpy float64 arrays of shape (ny, nx), row index
y, column index x. Defaults (silicon, tolerance 1e-10, periodic boundary) are the command
line's, so the same call gives the command line's numbers to the last bit. Bad input raises
:class:`asperity.Error` (a ``ValueError``) with the command line's one-line message, naming the
argument at fault; a value no contact problem has (``youngs=130``) is refused with the unit
likely meant, and an unusual one (a load pressing above 1e-3 E*, a contact cut by the window)
is a ``UserWarning`` through :mod:`warnings`. Solves release the GIL; Ctrl-C stops them.
Plotting needs matplotlib (``pip install .[plot]``).

``PRESETS``: the preset local laws, (name, mu_s, mu_d) tuples, for ``law=`` of ``onset`` and
``slide`` (illustrative placeholders, not measurements). ``__version__``: the package's
version, the same as that of the asperity library it is built from (``results.json`` states it).

>>> import asperity as ap
>>> t = ap.generate(size=31.13e-6, grid=256, hurst=0.8, rms=21e-9, rolloff=7e-6, cutoff=0.25e-6,
...                 sphere_radius=1.5e-3, seed=1)
>>> s = ap.contact(t, loads=[1e-3], hardness=12e9)[0]
>>> o = ap.onset(s, mu_s=0.6, mu_d=0.4)
>>> o.friction_drop  # doctest: +SKIP
"""

from __future__ import annotations

import json as _json
import os as _os
import warnings as _warnings
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Union

from ._asperity import (
    PRESETS,
    ClassShare,
    ContactSolution,
    Error,
    Onset,
    PartialSlip,
    Profile,
    Slide,
    Topography,
    __version__,
    compound,
    contact,
    generate,
    onset,
    psd,
    read_topography,
    slide,
)
from . import _asperity

__all__ = [
    "Error",
    "Topography",
    "Profile",
    "ContactSolution",
    "Onset",
    "ClassShare",
    "Slide",
    "PartialSlip",
    "PRESETS",
    "read_topography",
    "compound",
    "generate",
    "psd",
    "contact",
    "onset",
    "slide",
    "analyse_shs",
    "run_study",
    "__version__",
]


def analyse_shs(
    time_s: Sequence[float],
    friction_n: Sequence[float],
    normal_n: Sequence[float],
    displacement_m: Optional[Sequence[float]] = None,
    *,
    speed: float = 0.3e-6,
    window: float = 1e-6,
    window_start: float = 0.0,
    peak_within: float = 2e-6,
    min_duration: float = 1.0,
    hold_fraction: float = 0.2,
    slide_fraction: float = 0.5,
    group_tolerance: float = 0.25,
) -> List[Dict[str, float]]:
    """Find every hold and restart of a slide-hold-slide trace and measure each restart.

    ``time_s`` [s] (strictly increasing), ``friction_n`` and ``normal_n`` [N], and optionally
    the measured sliding ``displacement_m`` [m]; without it displacement is derived from time
    and ``speed`` [m/s]. F_S is the peak within ``peak_within`` [m] of sliding after the
    restart, F_D and N the means over ``window`` [m] starting ``window_start`` [m] after the
    peak (default 0: at the peak). Holds and slides shorter
    than ``min_duration`` [s] are noise; friction below ``hold_fraction`` of the sliding level
    is a hold, above ``slide_fraction`` sliding. Defaults are ``asperity shs``'s.

    Returns one dict per restart, in time order: ``hold_s``, ``static_force_n``,
    ``dynamic_force_n``, ``normal_force_n``, ``static_coefficient``, ``dynamic_coefficient``,
    ``friction_drop``, ``hold_start_s``, ``restart_s``, ``peak_s``, ``window_start_s``,
    ``window_end_s``. Holds that
    give no measurement are reported as warnings.
    """
    analysis = _json.loads(
        _asperity._analyse_shs(
            _floats(time_s, "time_s"),
            _floats(friction_n, "friction_n"),
            _floats(normal_n, "normal_n"),
            None if displacement_m is None else _floats(displacement_m, "displacement_m"),
            speed,
            window,
            window_start,
            peak_within,
            min_duration,
            hold_fraction,
            slide_fraction,
            group_tolerance,
        )
    )
    for reason in analysis["skipped"]:
        _warnings.warn(f"trace: {reason}", stacklevel=2)
    return analysis["cycles"]


def run_study(
    study: Union[str, "_os.PathLike[str]", Mapping[str, Any], None] = None,
    out: Union[str, "_os.PathLike[str]"] = "results",
    *,
    quick: bool = False,
    fresh: bool = False,
    progress: Union[bool, Callable[[Dict[str, Any]], None]] = False,
) -> List[Dict[str, Any]]:
    """Run a study, as ``asperity run``: every topography at every load, every local law.

    ``study``: a study file (TOML), a dict with the same keys and values (relative paths are
    then relative to the working directory), or None for the default study. Writes into
    ``out`` as the command line does (results.csv, results.json, study.toml, figures,
    index.html), reusing the solves earlier runs there computed with the same inputs (a study
    that was stopped resumes; one grown by a load solves that load); ``fresh`` starts over.
    ``quick`` runs it on 256 × 256 points with 7 loads. ``progress``: True prints one line per
    solve and elastic onset on stderr; a callable receives one dict per event (``{"event":
    "start", "total", "done", "work", "work_done", "onsets", "onsets_done"}``:
    the solves, their estimated work (grid points times 1 + the decades of load above the
    lowest) and the elastic onsets, and how
    many of each an earlier run did; ``{"event": "solved", "topography", "load_n",
    "iterations", "seconds", "work"}``; and with elastic sharing ``{"event": "slid",
    "topography", "load_n", "law", "iterations", "seconds"}`` per law before its solve's
    "solved", and while an onset runs, after its first second and at most every second,
    ``{"event": "sliding", "topography", "load_n", "law", "stage", "steps", "largest_drop",
    "seconds"}``, ``stage`` "march" or "search").
    Ctrl-C stops the run once the solves under way are recorded (an elastic onset under way
    stops at its next step, unrecorded); running it again resumes.

    Returns the rows of results.json: one dict per topography × sharing × law × load.
    """
    if isinstance(study, Mapping):
        study_file, study_json = None, _json.dumps(study)
    elif study is None:
        study_file, study_json = None, None
    else:
        study_file, study_json = _os.fspath(study), None
    callback = _print_progress() if progress is True else (progress or None)
    rows = _asperity._run_study(study_file, study_json, _os.fspath(out), quick, fresh, callback)
    return _json.loads(rows)


def _floats(values: Sequence[float], name: str) -> List[float]:
    import numpy as np

    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 1:
        raise Error(f"{name}: a 1-D sequence of numbers is needed, got {array.ndim} dimension(s)")
    return array.tolist()


def _print_progress() -> Callable[[Dict[str, Any]], None]:
    import sys

    state = {"done": 0, "total": 0}

    def report(event: Dict[str, Any]) -> None:
        if event["event"] == "start":
            state.update(done=event["done"], total=event["total"])
            onsets = f"; {event['onsets']} elastic onsets, {event['onsets_done']} done before" if event["onsets"] else ""
            print(f"asperity: {event['total']} solves, {event['done']} done before{onsets}", file=sys.stderr)
        elif event["event"] == "sliding":
            print(
                f"asperity: {event['topography']} at {event['load_n']:.3e} N: elastic onset of "
                f"\"{event['law']}\" under way, {event['stage']}, {event['steps']} steps, largest force "
                f"{event['largest_drop']:.4f} mu_d N, {event['seconds']:.0f} s",
                file=sys.stderr,
            )
        elif event["event"] == "slid":
            print(
                f"asperity: {event['topography']} at {event['load_n']:.3e} N: elastic onset of "
                f"\"{event['law']}\": {event['iterations']} iterations, {event['seconds']:.2f} s",
                file=sys.stderr,
            )
        else:
            state["done"] += 1
            print(
                f"asperity: [{state['done']}/{state['total']}] {event['topography']} at "
                f"{event['load_n']:.3e} N: {event['iterations']} iterations, {event['seconds']:.2f} s",
                file=sys.stderr,
            )

    return report
