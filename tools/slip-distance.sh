#!/usr/bin/env bash
# How much the slip-weakening distance d_c moves the elastic-sharing onset: the table of
# docs/physics.md ("What sets d_c").
#
# Surface: the default study's ball-1 alone (its synthetic spec, seed 1, 1500² of 20.75 nm over
# 31.13 µm, without its wafer), cropped to the central 512 × 512 points (10.63 µm, around its
# contact), free boundary, silicon on a rigid flat (E = 130 GPa, ν = 0.26), mu_s = 0.6,
# mu_d = 0.4, at 0.3 mN, d_c = 1, 2, 5 nm.
#
# Prints one line per d_c: d_c, contact points, the elastic drop, equal sharing's (the
# paper's instant drop) and equal sharing's under the same weakening, δ_peak [nm], and the
# counts of the classes stuck / critical / weakening / weakened at the peak.
#
# Usage: [LOAD=0.3mN] tools/slip-distance.sh [OUT]   (OUT: working folder, default
# target/slip-distance).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/target/slip-distance}
load=${LOAD:-0.3mN}
cargo build --release --quiet --manifest-path "$root/Cargo.toml" --bin asperity
bin=$root/target/release/asperity
mkdir -p "$out"
cd "$out"

"$bin" topo generate --size 31.13um --grid 1500 --hurst 0.8 --rms 21nm --rolloff 7um --cutoff 0.25um \
  --sphere-radius 1.5mm --seed 1 ball1.npy >/dev/null
"$bin" topo convert ball1.npy --size 31.13um --crop 494:1006,494:1006 ball1-512.npy >/dev/null
for dc in 1nm 2nm 5nm; do
  "$bin" slide ball1-512.npy --size 10.6257066667um --free --load "$load" --mu-s 0.6 --mu-d 0.4 \
    --slip-distance "$dc" --out "slide-$dc" 2>/dev/null
  python3 - "slide-$dc/slide.json" "$dc" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
classes = " / ".join(str(j[c]["count"]) for c in ("stuck", "critical", "weakening", "weakened"))
print(f"d_c {sys.argv[2]}: {j['contact_points']} points, elastic drop {j['friction_drop']:.4f}, "
      f"equal {j['equal_sharing']['friction_drop']:.4f}, equal with d_c {j['equal_sharing_same_law']['friction_drop']:.4f}, "
      f"δ_peak {j['peak_displacement_m'] * 1e9:.2f} nm, stuck / critical / weakening / weakened {classes}")
PY
done
