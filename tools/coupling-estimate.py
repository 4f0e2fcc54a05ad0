#!/usr/bin/env python3
"""How large the normal–tangential coupling is that asperity neglects (Goodman's approximation):
one pass of it, on the paper's silicon against a rigid flat.

asperity solves the normal contact, then the shear on the pressure it found, as if the shear did
not move the surface normally. For two identical bodies that is exact; for silicon on a rigid
flat (Dundurs' β = (1 − 2ν)/(2(1 − ν)) = 0.32) a shear traction q on the elastic surface lifts it
ahead of each point and lowers it behind (Cerruti's solution for a tangential point force Q along
x, Johnson, Contact Mechanics, 1985, ch. 3: u_z = −(1 − 2ν)/(4πG) · Q x/ρ², u_z into the body),
which changes the gap and so the pressure that bounds the shear.

This script takes the shear at the peak of the elastic-sharing onset (`asperity slide`), adds the
normal displacement it causes to the heights (pixel forces through the point-force kernel,
averaged over 4 × 4 points of each source pixel, on the zero-padded grid of a free window),
solves the contact again at the same load, and runs the onset again on the new pressure. The
change of each friction drop is the coupling's first-order effect: one pass of a fixed point that
the coupled problem would iterate to its end.

Surface: the default study's ball-1 alone (seed 1, 1500² of 20.75 nm over 31.13 µm, without its
wafer) cropped to the central 512² (10.63 µm), free boundary, E = 130 GPa, ν = 0.26 on a rigid
flat, mu_s = 0.6, mu_d = 0.4, d_c = 2 nm, at the loads given (default 0.3 mN and 3 mN).

Usage: tools/coupling-estimate.py [--loads 0.3mN,3mN] [OUT]
  OUT  working folder (default target/coupling-estimate). Needs numpy; builds the release binary.
       About 6 minutes on 2 cores (the two onsets at 3 mN most of it).
Prints one line per load: contact points before and after, the relative L2 change of the
pressure, and the three drops (equal sharing with the instant drop, equal with d_c, elastic with
d_c) before → after.
"""

import argparse
import json
import os
import subprocess

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "asperity")
SIZE = "10.6257066667um"
YOUNGS, POISSON = 130e9, 0.26


def asperity(*args, cwd):
    subprocess.run([BIN, *args], check=True, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def normal_displacement(qx, qy, pixel):
    """u_z [m, into the body] of the free half-space under the pixel tractions qx, qy [Pa]."""
    ny, nx = qx.shape
    shear_modulus = YOUNGS / (2.0 * (1.0 + POISSON))
    # Offsets on the padded (2ny, 2nx) grid, wrapped so that a linear convolution results.
    oy = np.fft.fftfreq(2 * ny, 1.0 / (2 * ny))[:, None] * pixel
    ox = np.fft.fftfreq(2 * nx, 1.0 / (2 * nx))[None, :] * pixel
    kx = np.zeros((2 * ny, 2 * nx))
    ky = np.zeros((2 * ny, 2 * nx))
    sub = (np.arange(4) + 0.5) / 4.0 - 0.5
    for sy in sub:
        for sx in sub:
            dx, dy = ox - sx * pixel, oy - sy * pixel
            r2 = dx * dx + dy * dy
            kx += dx / r2
            ky += dy / r2
    factor = -(1.0 - 2.0 * POISSON) / (4.0 * np.pi * shear_modulus) / 16.0
    area = pixel * pixel
    pad = lambda q: np.pad(q * area, ((0, ny), (0, nx)))
    spectrum = np.fft.rfft2(pad(qx)) * np.fft.rfft2(factor * kx) + np.fft.rfft2(pad(qy)) * np.fft.rfft2(factor * ky)
    return np.fft.irfft2(spectrum, s=(2 * ny, 2 * nx))[:ny, :nx]


def check_kernel(pixel):
    """The convolution against the point-force formula for one pixel force, 20 pixels away."""
    n = 64
    qx = np.zeros((n, n))
    qx[32, 32] = 1e9
    u = normal_displacement(qx, np.zeros((n, n)), pixel)
    shear_modulus = YOUNGS / (2.0 * (1.0 + POISSON))
    want = -(1.0 - 2.0 * POISSON) / (4.0 * np.pi * shear_modulus) * 1e9 * pixel * pixel * (20 * pixel) / (20 * pixel) ** 2
    got = u[32, 52]
    assert abs(got / want - 1.0) < 1e-3, (got, want)
    assert abs(u[52, 32]) < 1e-12 * abs(want) + 1e-30, u[52, 32]


def onset(folder, load, cwd):
    asperity("slide", folder, "--load", load, "--mu-s", "0.6", "--mu-d", "0.4", "--slip-distance", "2nm",
             "--out", folder + "-slide", cwd=cwd)
    with open(os.path.join(cwd, folder + "-slide", "slide.json")) as f:
        j = json.load(f)
    return j, [j["equal_sharing"]["friction_drop"], j["equal_sharing_same_law"]["friction_drop"], j["friction_drop"]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--loads", default="0.3mN,3mN")
    parser.add_argument("out", nargs="?", default=os.path.join(ROOT, "target", "coupling-estimate"))
    args = parser.parse_args()
    subprocess.run(["cargo", "build", "--release", "--quiet", "--bin", "asperity"], check=True, cwd=ROOT)
    os.makedirs(args.out, exist_ok=True)
    cwd = args.out
    asperity("topo", "generate", "--size", "31.13um", "--grid", "1500", "--hurst", "0.8", "--rms", "21nm",
             "--rolloff", "7um", "--cutoff", "0.25um", "--sphere-radius", "1.5mm", "--seed", "1", "ball1.npy", cwd=cwd)
    asperity("topo", "convert", "ball1.npy", "--size", "31.13um", "--crop", "494:1006,494:1006", "ball1-512.npy",
             cwd=cwd)
    heights = np.load(os.path.join(cwd, "ball1-512.npy"))
    pixel = 31.13e-6 / 1500
    check_kernel(pixel)
    for load in args.loads.split(","):
        asperity("contact", "ball1-512.npy", "--size", SIZE, "--free", "--load", load, "--out", f"c0-{load}", cwd=cwd)
        before, drops0 = onset(f"c0-{load}", load, cwd)
        qx = np.load(os.path.join(cwd, f"c0-{load}-slide", "shear_x.npy"))
        qy = np.load(os.path.join(cwd, f"c0-{load}-slide", "shear_y.npy"))
        # The surface lifted towards the flat (u_z < 0) closes the gap as higher heights would.
        coupled = heights - normal_displacement(qx, qy, pixel)
        np.save(os.path.join(cwd, f"coupled-{load}.npy"), coupled)
        asperity("contact", f"coupled-{load}.npy", "--size", SIZE, "--free", "--load", load, "--out", f"c1-{load}",
                 cwd=cwd)
        after, drops1 = onset(f"c1-{load}", load, cwd)
        p0 = np.load(os.path.join(cwd, f"c0-{load}", "pressure-000.npy"))
        p1 = np.load(os.path.join(cwd, f"c1-{load}", "pressure-000.npy"))
        change = np.linalg.norm(p1 - p0) / np.linalg.norm(p0)
        names = ["equal, instant", "equal, d_c 2 nm", "elastic, d_c 2 nm"]
        drops = ", ".join(f"{n} {a:.4f} → {b:.4f} ({b - a:+.4f})" for n, a, b in zip(names, drops0, drops1))
        print(f"{load}: {before['contact_points']} → {after['contact_points']} points, pressure moved by "
              f"{change:.3f} (relative L2); drops {drops}")


if __name__ == "__main__":
    main()
