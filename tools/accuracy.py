#!/usr/bin/env python3
"""How accurate asperity's numbers are: the measurements behind every accuracy statement of the
guide (docs/accuracy.md), each with its conditions.

  contact  the default study (equal sharing, 1500², 25 loads, 3 balls) solved to its default
           contact tolerance 1e-8 and to 1e-12: how far the friction drop and the static
           coefficient move, per load range, and whether the contact points and element classes
           change.
  slide    `asperity slide` on the default study's ball-1 at 0.1 and 1 mN (contact solved to
           1e-12), the instant drop and d_c = 2 nm, at its default tolerance 1e-6 and at 1e-8:
           how far F_S and the peak displacement move, and how many elements change class.
  pixel    tools/sharing-convergence.sh at 0.03, 0.1 and 0.4 mN (ball-1's contact resampled to
           pixels of 41.5, 20.75 and 10.4 nm; the instant drop and d_c = 1, 2, 5 nm): how far the
           elastic-sharing drop moves from the study's pixel to half of it. An
           OUT/pixel/sharing-convergence.csv already there is read instead.
  psd      `topo info --psd-fit` on synthetic maps (512², 10 µm, 1 nm RMS) written as .gsf, so
           read as a non-periodic file (Hann window): Hurst exponents 0.5, 0.65, 0.8, 0.95,
           roll-offs at L/4, L/8 and L/16, six seeds each (72 maps): the error of H and of the
           roll-off wavelength.
  stiffness  the stuck tangential stiffness K_t of one round patch against Mindlin's
           8Ga/(2 − ν), for patch radii of 1.5 to 32 pixels
           (`cargo run --release --example stiffness_mindlin`).

Usage: tools/accuracy.py [--only PART[,PART…]] [OUT]
  OUT  working folder (default target/accuracy); writes OUT/accuracy.json and prints the
       tables of docs/accuracy.md (Markdown) with the command, version, commit and date.

Most of its time goes to the two default studies and the pixel's onsets at 10.4 nm.
Standard library only (Python ≥ 3.8); builds the release binary and the example with cargo.
"""

import argparse
import csv
import datetime
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "asperity")
PARTS = ["contact", "slide", "pixel", "psd", "stiffness"]


def run(args, **kw):
    return subprocess.run(args, check=True, text=True, stdout=subprocess.PIPE, **kw).stdout


def asperity(*args, cwd=None):
    return run([BIN, *args], cwd=cwd)


def rows_by_key(results_json):
    with open(results_json) as f:
        rows = json.load(f)["rows"]
    return {(r["topography"], r["law"], r["sharing"], r["load_n"]): r for r in rows}


def npy_data(path):
    """The data bytes of a .npy file (format 1.0 or 2.0): one byte per element of classes.npy."""
    raw = open(path, "rb").read()
    assert raw[:6] == b"\x93NUMPY", path
    if raw[6] == 1:
        return raw[10 + int.from_bytes(raw[8:10], "little"):]
    return raw[12 + int.from_bytes(raw[8:12], "little"):]


def rel(a, b):
    return abs(a - b) / abs(b)


def contact_part(out):
    """The default study at contact tolerance 1e-8 (its default) and 1e-12."""
    default = asperity("run", "--print-default")
    found = {}
    for tol in ["1e-8", "1e-12"]:
        study = os.path.join(out, f"study-{tol}.toml")
        text = default.replace("tolerance = 1e-8", f"tolerance = {tol}")
        assert f"tolerance = {tol}" in text, "the default study's tolerance line changed"
        # Only the table: the figures do not depend on the tolerance's effect.
        text = "\n".join(l for l in text.splitlines() if not l.startswith("figures = ")) + "\nfigures = []\n"
        with open(study, "w") as f:
            f.write(text)
        dir_ = os.path.join(out, f"study-{tol}")
        run([BIN, "run", study, "--out", dir_, "--fresh"] if os.path.isdir(dir_) else [BIN, "run", study, "--out", dir_])
        found[tol] = rows_by_key(os.path.join(dir_, "results.json"))
    loose, tight = found["1e-8"], found["1e-12"]
    ranges = [("below 1.78 µN", 0, 1.78e-6 * 0.999), ("1.78 µN – 100 mN", 1.78e-6 * 0.999, 1.0)]
    table = []
    for name, lo, hi in ranges:
        keys = [k for k in tight if lo <= k[3] < hi]
        drop = max(rel(loose[k]["friction_drop"], tight[k]["friction_drop"]) for k in keys)
        mu = max(rel(loose[k]["static_coefficient"], tight[k]["static_coefficient"]) for k in keys)
        points = sum(loose[k]["contact_points"] != tight[k]["contact_points"] for k in keys)
        table.append({"loads": name, "rows": len(keys), "max_rel_drop": drop, "max_rel_static": mu,
                      "rows_with_other_points": points})
    return table


def slide_part(out):
    """`slide` at tolerance 1e-6 (its default) and 1e-8 on ball-1 at 0.1 and 1 mN."""
    ball = os.path.join(out, "ball-1.npy")
    wafer = os.path.join(out, "wafer-1.gsf")
    if not os.path.exists(ball):
        asperity("topo", "generate", "--size", "31.13um", "--grid", "1500", "--hurst", "0.8", "--rms", "21nm",
                 "--rolloff", "7um", "--cutoff", "0.25um", "--sphere-radius", "1.5mm", "--seed", "1", ball)
        asperity("topo", "generate", "--size", "31.13um", "--grid", "1500", "--hurst", "0.8", "--rms", "0.2nm",
                 "--rolloff", "5um", "--seed", "101", wafer)
    contact = os.path.join(out, "contact-ball-1")
    asperity("contact", ball, "--size", "31.13um", "--wafer", wafer, "--load", "0.1mN,1mN", "--tolerance", "1e-12",
             "--out", contact)
    table = []
    for load in ["0.1mN", "1mN"]:
        for weakening in [[], ["--slip-distance", "2nm"]]:
            got = {}
            for tol in ["1e-6", "1e-8"]:
                name = f"slide-{load}-{'dc' if weakening else 'instant'}-{tol}"
                dir_ = os.path.join(out, name)
                asperity("slide", contact, "--load", load, "--mu-s", "0.6", "--mu-d", "0.4",
                         *(weakening or ["--slip-distance", "0"]), "--tolerance", tol, "--out", dir_)
                with open(os.path.join(dir_, "slide.json")) as f:
                    got[tol] = json.load(f)
                got[tol]["classes_map"] = npy_data(os.path.join(dir_, "classes.npy"))
            a, b = got["1e-6"], got["1e-8"]
            changed = sum(x != y for x, y in zip(a["classes_map"], b["classes_map"]))
            table.append({
                "load": load, "weakening": "d_c 2 nm" if weakening else "instant",
                "contact_points": b["contact_points"],
                "rel_static_force": rel(a["static_force_n"], b["static_force_n"]),
                "rel_peak_displacement": (rel(a["peak_displacement_m"], b["peak_displacement_m"])
                                          if a["peak_displacement_m"] and b["peak_displacement_m"] else None),
                "elements_changing_class": changed,
            })
    return table


def pixel_part(out):
    """The elastic-sharing drop against the pixel (tools/sharing-convergence.sh)."""
    folder = os.path.join(out, "pixel")
    table = os.path.join(folder, "sharing-convergence.csv")
    if not os.path.exists(table):
        env = dict(os.environ, LOADS="0.03mN 0.1mN 0.4mN")
        subprocess.run([os.path.join(ROOT, "tools", "sharing-convergence.sh"), folder,
                        os.path.join(folder, "sharing-convergence.png")], check=True, env=env, stdout=sys.stderr)
    rows = list(csv.DictReader(open(table)))
    found = []
    for load in sorted({float(r["load_n"]) for r in rows}):
        these = [r for r in rows if float(r["load_n"]) == load]
        points = [int(r["contact_points"]) for r in sorted(these, key=lambda r: int(r["grid"]))
                  if float(r["slip_distance_m"]) == 0]
        models = [("instant", 0.0, "friction_drop")] + [
            (f"d_c {dc * 1e9:g} nm", dc, "friction_drop")
            for dc in sorted({float(r["slip_distance_m"]) for r in these}) if dc > 0] + [
            ("equal sharing, instant", 0.0, "equal_friction_drop")]
        for name, dc, column in models:
            by = {int(r["grid"]): float(r[column]) for r in these if float(r["slip_distance_m"]) == dc}
            found.append({"load_n": load, "contact_points": points, "model": name,
                          "drops": [by[n] for n in sorted(by)], "rel_change_last": rel(by[400], by[200])})
    return found


def psd_part(out):
    """`--psd-fit` on 72 synthetic maps read as files (Hann window)."""
    size = 10e-6
    results = []
    for hurst in [0.5, 0.65, 0.8, 0.95]:
        for parts in [4, 8, 16]:
            rolloff = size / parts
            for seed in range(1, 7):
                path = os.path.join(out, f"psd-{hurst}-{parts}-{seed}.gsf")
                asperity("topo", "generate", "--size", "10um", "--grid", "512", "--hurst", str(hurst), "--rms", "1nm",
                         "--rolloff", f"{rolloff:.6e}", "--seed", str(seed), path)
                fit = json.loads(asperity("topo", "info", path, "--psd-fit", "--json"))["psd_fit"]
                results.append({"hurst": hurst, "rolloff_m": rolloff, "seed": seed,
                                "fit_hurst": fit["hurst"], "fit_rolloff_m": fit["rolloff_wavelength_m"],
                                "refusal": fit["refusal"]})
    def summary(group):
        these = [r for r in group if r["refusal"] is None]
        dh = [r["fit_hurst"] - r["hurst"] for r in these]
        dr = [r["fit_rolloff_m"] / r["rolloff_m"] - 1 for r in these if r["fit_rolloff_m"]]
        return {"maps": len(group), "fitted": len(these), "mean_dh": statistics.mean(dh),
                "max_abs_dh": max(map(abs, dh)), "rolloff_found": len(dr),
                "median_abs_drolloff": statistics.median(map(abs, dr)) if dr else None,
                "max_abs_drolloff": max(map(abs, dr)) if dr else None}

    by_hurst = [{"group": f"H = {h}", **summary([r for r in results if r["hurst"] == h])}
                for h in [0.5, 0.65, 0.8, 0.95]]
    by_rolloff = [{"group": f"λ_r = L/{parts}", **summary([r for r in results if r["rolloff_m"] == size / parts])}
                  for parts in [4, 8, 16]]
    return {"groups": by_hurst + by_rolloff + [{"group": "all", **summary(results)}], "maps": results}


def stiffness_part(out):
    text = run(["cargo", "run", "--release", "--quiet", "--example", "stiffness_mindlin"], cwd=ROOT)
    return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(text.splitlines())]


def provenance():
    commit = run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"]).strip()
    # The code the numbers depend on; the docs and tools may differ from the commit.
    dirty = run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no", "--", "src", "examples",
                 "Cargo.toml", "Cargo.lock"]).strip()
    version = asperity("--version").split()[1]
    date = datetime.date.today().isoformat()
    return f"asperity {version}, commit {commit}{' (uncommitted changes)' if dirty else ''}, {date}"


def markdown(found, made):
    lines = []
    if "contact" in found:
        lines += ["| loads | rows | friction drop, largest relative change | static coefficient | rows with other contact points |",
                  "|---|---|---|---|---|"]
        for r in found["contact"]:
            lines.append(f"| {r['loads']} | {r['rows']} | {r['max_rel_drop']:.1e} | {r['max_rel_static']:.1e} | "
                         f"{r['rows_with_other_points']} |")
        lines.append("")
    if "slide" in found:
        lines += ["| load | weakening | contact points | F_S, relative change | δ at the peak, relative change | elements changing class |",
                  "|---|---|---|---|---|---|"]
        for r in found["slide"]:
            d = "—" if r["rel_peak_displacement"] is None else f"{r['rel_peak_displacement']:.1e}"
            lines.append(f"| {r['load']} | {r['weakening']} | {r['contact_points']} | {r['rel_static_force']:.1e} | "
                         f"{d} | {r['elements_changing_class']} |")
        lines.append("")
    if "pixel" in found:
        lines += ["| load | contact points (41.5 / 20.75 / 10.4 nm) | model | drop at 41.5 nm | 20.75 nm | 10.4 nm | change from 20.75 to 10.4 nm |",
                  "|---|---|---|---:|---:|---:|---:|"]
        for r in found["pixel"]:
            d = " | ".join(f"{x:.4f}" for x in r["drops"])
            lines.append(f"| {r['load_n'] * 1e3:g} mN | {' / '.join(map(str, r['contact_points']))} | {r['model']} | {d} | "
                         f"{r['rel_change_last']:.1e} |")
        lines.append("")
    if "psd" in found:
        lines += ["| maps | count | fitted | mean error of H | largest error of H | roll-off found | median error of λ_r | largest error of λ_r |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in found["psd"]["groups"]:
            med = "—" if r["median_abs_drolloff"] is None else f"{100 * r['median_abs_drolloff']:.1f} %"
            mx = "—" if r["max_abs_drolloff"] is None else f"{100 * r['max_abs_drolloff']:.1f} %"
            lines.append(f"| {r['group']} | {r['maps']} | {r['fitted']} | {r['mean_dh']:+.3f} | {r['max_abs_dh']:.3f} | "
                         f"{r['rolloff_found']} | {med} | {mx} |")
        lines.append("")
    if "stiffness" in found:
        lines += ["| patch radius [px] | points | K_t / Mindlin |", "|---|---|---|"]
        for r in found["stiffness"]:
            lines.append(f"| {r['radius_px']:g} | {int(r['points'])} | {r['ratio']:.4f} |")
        lines.append("")
    lines.append(f"Measured by `{made}` with {provenance()}.")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=os.path.join(ROOT, "target", "accuracy"))
    parser.add_argument("--only", default=",".join(PARTS), help="parts to run, comma-separated: " + ", ".join(PARTS))
    args = parser.parse_args()
    parts = args.only.split(",")
    for p in parts:
        if p not in PARTS:
            sys.exit(f"--only: unknown part {p!r} (parts: {', '.join(PARTS)})")
    os.makedirs(args.out, exist_ok=True)
    subprocess.run(["cargo", "build", "--release", "--quiet", "--bin", "asperity"], cwd=ROOT, check=True)
    found = {}
    for p in parts:
        print(f"accuracy: {p} …", file=sys.stderr, flush=True)
        found[p] = globals()[f"{p}_part"](args.out)
    with open(os.path.join(args.out, "accuracy.json"), "w") as f:
        json.dump(found, f, indent=1)
    made = "tools/accuracy.py" + ("" if parts == PARTS else f" --only {args.only}")
    print(markdown(found, made))


if __name__ == "__main__":
    main()
