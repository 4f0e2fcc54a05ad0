#!/usr/bin/env python3
"""Compare asperity's reading of SurfaceTopography's example files with SurfaceTopography's own.

    python tools/st-compare.py PATH/TO/SurfaceTopography/test/file_format_examples [--asperity BIN]

Run it with a Python where SurfaceTopography is installed. For every file of the folder (a zip
container: for each member), read it with SurfaceTopography (`read_topography`; a `.gz` through
`gzip.open`, as its own tests do; a member extracted to a temporary folder) and with
`asperity topo info --json FILE`, and classify:

- same: same kind (map or profile), grid (nx, ny or points), physical size in metres, and the
  heights' mean, rms, min and max within 1e-9 relative (the mean within 1e-9 of the rms; a
  profile's rms is SurfaceTopography's rms_height_from_profile), after the same unit conversion;
- same*: the same numbers, with a documented deliberate difference (a bare array's grid read
  as (ny, nx); another default channel, compared on SurfaceTopography's; a profile read on the
  grid of the step its header states, the same points and heights);
- refused: asperity refuses in one line (SurfaceTopography's outcome is shown beside it);
- ST fails: SurfaceTopography cannot read the file (asperity's outcome shown);
- DIFFERENT: both read it and a number differs (the numbers are printed).

Prints a table and the totals.
"""

import argparse
import gzip
import json
import math
import os
import subprocess
import sys
import tempfile
import warnings
import zipfile

import numpy as np

warnings.simplefilter("ignore")

from SurfaceTopography import open_topography  # noqa: E402

# Metres per unit, for SurfaceTopography's unit names.
METRES = {"km": 1e3, "m": 1.0, "cm": 1e-2, "mm": 1e-3, "µm": 1e-6, "um": 1e-6, "μm": 1e-6, "micron": 1e-6,
          "microns": 1e-6, "nm": 1e-9,
          "Å": 1e-10, "A": 1e-10, "pm": 1e-12}

REL = 1e-9


def st_read(path, member_of=None):
    """SurfaceTopography's reading of `path`: a dict, or the reason it fails."""
    try:
        source = gzip.open(path) if path.endswith(".gz") else path
        reader = open_topography(source)
        default = reader.default_channel
        t = reader.topography()
        h = t.heights()
        defined = np.ma.compressed(h) if np.ma.isMaskedArray(h) else np.asarray(h).ravel()
        defined = defined[np.isfinite(defined)]
        scale = METRES.get(t.unit) if t.unit is not None else None
        out = {
            "dim": t.dim,
            "grid": list(t.nb_grid_pts) + ([1] if t.dim == 1 else []),
            "size": [float(s) for s in t.physical_sizes] if t.physical_sizes is not None else None,
            "unit": t.unit,
            "scale": scale,
            "channel": default.name,
            "channel_index": default.index,
            "mean": float(t.mean()),
            "rms": float(t.rms_height_from_profile()) if t.dim == 1 else float(np.std(defined)),
            "min": float(defined.min()),
            "max": float(defined.max()),
        }
        return out
    except Exception as e:  # noqa: BLE001 (any failure of SurfaceTopography is its verdict)
        return f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}"[:120]


def asperity(binary, path, extra=()):
    """asperity's `topo info --json`: (dict, None) or (None, its error line)."""
    try:
        p = subprocess.run([binary, "topo", "info", "--json", path, *extra], capture_output=True, timeout=300)
    except subprocess.TimeoutExpired:
        return None, "timed out"
    if p.returncode != 0:
        err = p.stderr.decode("utf-8", "replace").strip()
        lines = err.splitlines()
        return None, (lines[0] if len(lines) == 1 else f"NOT ONE LINE ({len(lines)}): {err[:200]}")
    return json.loads(p.stdout), None


def close(a, b, rel=REL, scale=None):
    # None (asperity) and NaN (SurfaceTopography) both say "not defined".
    if a is None or b is None or math.isnan(b):
        return a is None and (b is None or math.isnan(b))
    ref = abs(scale) if scale is not None else max(abs(a), abs(b))
    return abs(a - b) <= rel * ref or a == b


def compare(st, a, transposed=False, unitless=False):
    """The differences between SurfaceTopography's reading and asperity's, as text. `unitless`:
    compare asperity's values in the units it read from the file with SurfaceTopography's
    values as stored (a file whose units SurfaceTopography does not read)."""
    diffs = []
    if unitless:
        a = dict(a)
        for unit_key, known_key, keys in (("height_unit", "height_unit_known", ("mean", "rms", "min", "max")),
                                          ("position_unit", None, ("length",))):
            per = METRES.get(a.get(unit_key) or "")
            if per is None or a.get(keys[0] + "_m") is None:
                continue
            for k in keys:
                a[k] = None if a[k + "_m"] is None else a[k + "_m"] / per
                a[k + "_m"] = None
            if known_key:
                a[known_key] = False
    profile = st["dim"] == 1
    if a["kind"] != ("profile" if profile else "map"):
        return [f"kind {a['kind']} vs ST dim {st['dim']}"]
    grid = [a["points"], 1] if profile else [a["nx"], a["ny"]]
    want = st["grid"][::-1] if transposed else st["grid"]
    if grid != want:
        diffs.append(f"grid {grid} vs {want}")
    known = a["height_unit_known"]
    s = st["scale"] if known else 1.0
    if known and s is None:
        return [f"asperity knows the unit ({a['height_unit']}), ST's is {st['unit']!r}"]
    suffix = "_m" if known else ""
    if profile:
        length = a.get("length_m" if a.get("length_m") is not None else "length")
        want_len = st["size"][0] * (st["scale"] or 1.0) if a.get("length_m") is not None else st["size"][0]
        if st["size"] is not None and not close(length, want_len):
            diffs.append(f"length {length!r} vs {want_len!r}")
    else:
        size = a["physical_size_m"]
        want_size = None if st["size"] is None or st["scale"] is None else [x * st["scale"] for x in st["size"]]
        if transposed and want_size:
            want_size = want_size[::-1]
        if (size is None) != (want_size is None) or (size and not all(map(close, size, want_size))):
            diffs.append(f"size {size} vs {want_size}")
    for key in ("mean", "rms", "min", "max"):
        got = a.get(key + suffix)
        ref = st[key] * s
        spread = st["rms"] * s if key == "mean" else None
        if not close(got, ref, scale=spread if spread else None):
            diffs.append(f"{key} {got!r} vs {ref!r}")
    return diffs


def classify(binary, path, label, st):
    a, err = asperity(binary, path)
    if err is not None:
        verdict = "refused" if not err.startswith("NOT ONE LINE") and err != "timed out" else "DIFFERENT"
        st_text = "ST fails" if isinstance(st, str) else f"ST reads (dim {st['dim']}, {st['grid']})"
        return verdict, f"{st_text}; asperity: {err[:160]}"
    if a.get("kind") == "container":
        return None, a
    if isinstance(st, str):
        return "ST fails", f"ST: {st}; asperity: {a['kind']} {a.get('nx', a.get('points'))}"
    diffs = compare(st, a)
    if not diffs:
        return "same", ""
    # Units the file states that SurfaceTopography does not read (a CSV's column names).
    if st["unit"] is None and not compare(st, a, unitless=True):
        units = {a.get("position_unit"), a.get("height_unit")} - {None}
        return "same*", f"asperity reads the unit(s) {sorted(units)} the file states, ST none; same values as stored"
    # A step the header states, which the rounded positions agree with (a Dektak export):
    # asperity reads the profile on that grid, ST on the rounded positions. The same points and
    # the same heights (min, max); length and statistics differ as the grid and the positions do.
    if a["kind"] == "profile" and a.get("uniform") and a.get("on_stated_grid"):
        same = [k for k in ("min", "max") if close(a.get(k + "_m"), st[k] * (st["scale"] or 1.0))]
        if a["points"] == st["grid"][0] and len(same) == 2:
            return "same*", f"read on the grid of the step its header states (ST: the rounded positions); {'; '.join(diffs)}"
    # A bare array (npy, npz, h5) is (ny, nx) for asperity, (nx, ny) for SurfaceTopography.
    if a["format"] in ("npy", "npz", "hdf5") and not compare(st, a, transposed=True):
        return "same*", "grid transposed: asperity reads a bare array as (ny, nx)"
    # Another default channel: compare SurfaceTopography's.
    if a.get("channels") and a["channel"] != st["channel"]:
        a2, err2 = asperity(binary, path, ["--channel", str(st["channel_index"])])
        if a2 is not None and not compare(st, a2):
            return "same*", f"default channel {a['channel']!r} (ST: {st['channel']!r}), same on ST's"
    return "DIFFERENT", "; ".join(diffs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("--asperity", default=os.path.join(os.path.dirname(__file__), "..", "target", "release", "asperity"))
    args = ap.parse_args()
    rows = []
    for name in sorted(os.listdir(args.folder)):
        path = os.path.join(args.folder, name)
        if not os.path.isfile(path):
            continue
        st = st_read(path)
        verdict, detail = classify(args.asperity, path, name, st)
        if verdict is None:  # a container: each member, against ST on the extracted file
            with tempfile.TemporaryDirectory() as tmp, zipfile.ZipFile(path) as z:
                for m in detail["members"]:
                    member = m["name"]
                    label = f"{name}#{member}"
                    target = z.extract(member, tmp)
                    v, d = classify(args.asperity, f"{path}#{member}", label, st_read(target))
                    rows.append((label, v, d))
            continue
        rows.append((name, verdict, detail))
    width = max(len(r[0]) for r in rows)
    print(f"{'file':<{width}}  {'class':<9}  detail")
    for label, verdict, detail in rows:
        print(f"{label:<{width}}  {verdict:<9}  {detail}")
    totals = {}
    for _, verdict, _ in rows:
        totals[verdict] = totals.get(verdict, 0) + 1
    print()
    print(f"{len(rows)} files: " + ", ".join(f"{k} {v}" for k, v in sorted(totals.items())))
    return 1 if totals.get("DIFFERENT") else 0


if __name__ == "__main__":
    sys.exit(main())
