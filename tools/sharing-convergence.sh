#!/usr/bin/env bash
# Convergence of the elastic-sharing onset with the pixel size.
#
# With an instant drop from mu_s to mu_d the onset under elastic sharing has no length of its
# own: its slip front is set by the pixel. A slip-weakening distance d_c gives it one, the
# nucleation length L_c ~ G d_c / ((mu_s - mu_d) p), and the onset converges once the pixel
# resolves L_c. This script measures both on one default surface resampled to three pixel
# sizes over the same window.
#
# Surface: the default study's ball-1 (its synthetic spec, seed 1, 1500² over 31.13 µm)
# compounded with its wafer (seed 101), cropped to columns 525:725 and rows 856:1056
# (a 4.1507 µm square, x 10.90–15.05 µm, y 17.76–21.91 µm, around ball-1's contact up to
# 0.4 mN: at 0.4 mN its 361 elements lie within x 11.85–14.11 µm, y 19.09–20.57 µm), then
# resampled (cubic) to 100², 200² and 400² points: pixels of 41.51, 20.75 (the study's) and
# 10.38 nm. The roughness has no wavelength below 0.25 µm, so the resampled surfaces are the
# same surface. Periodic window, silicon (E = 130 GPa, ν = 0.26 on a rigid flat), law
# "hold 100 s" (mu_s = 0.6, mu_d = 0.4), loads 0.1 and 0.4 mN, the instant drop and
# d_c = 1, 2, 5 nm.
#
# Writes OUT/sharing-convergence.csv (one row per pixel × load × weakening: pixel_size_m,
# grid, load_n, slip_distance_m (0: instant drop), contact_points, static_coefficient,
# friction_drop, equal_static_coefficient, equal_friction_drop (equal sharing on the same
# pressure), seconds) and the figure FIGURE (PNG, with its SVG beside it) through
# `cargo run --release --example sharing_convergence`.
#
# Usage: [LOADS="0.1mN 0.4mN"] tools/sharing-convergence.sh [OUT [FIGURE]]
#   OUT     working folder (default target/sharing-convergence)
#   FIGURE  default docs/figures/sharing-convergence.png
# Takes about 6 minutes on a 2-core machine (the 10.38 nm onsets at 0.4 mN with d_c most).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/target/sharing-convergence}
figure=${2:-$root/docs/figures/sharing-convergence.png}
cargo build --release --quiet --manifest-path "$root/Cargo.toml" --bin asperity
bin=$root/target/release/asperity
mkdir -p "$out"
cd "$out"

# The default study's ball-1 and its wafer (src/study/default.toml).
"$bin" topo generate --size 31.13um --grid 1500 --hurst 0.8 --rms 21nm --rolloff 7um --cutoff 0.25um \
    --sphere-radius 1.5mm --seed 1 ball-1.npy
"$bin" topo generate --size 31.13um --grid 1500 --hurst 0.8 --rms 0.2nm --rolloff 5um --seed 101 wafer-1.gsf
crop=525:725,856:1056
# The wafer cropped to the same window: compounding centres the two windows on each other.
"$bin" topo convert wafer-1.gsf --crop $crop wafer-window.gsf

# LOADS (space-separated) measures other loads, e.g. LOADS="0.03mN" for a contact of few patches.
read -r -a loads <<<"${LOADS:-0.1mN 0.4mN}"
weakenings=(instant 1nm 2nm 5nm)
csv=sharing-convergence.csv
echo "pixel_size_m,grid,load_n,slip_distance_m,contact_points,static_coefficient,friction_drop,equal_static_coefficient,equal_friction_drop,seconds" >"$csv.part"
for n in 100 200 400; do
    pixel=$(awk -v n=$n 'BEGIN { printf "%.12e", 200 * 31.13e-6 / 1500 / n }')
    "$bin" contact ball-1.npy --size 31.13um --crop $crop --pixel-size "$pixel" --wafer wafer-window.gsf \
        $(printf -- '--load %s ' "${loads[@]}") --out "contact-$n"
    for load in "${loads[@]}"; do
        for w in "${weakenings[@]}"; do
            run="slide-$n-$load-$w"
            if [ "$w" = instant ]; then dc=(--slip-distance 0); else dc=(--slip-distance "$w"); fi
            "$bin" slide "contact-$n" --load "$load" --mu-s 0.6 --mu-d 0.4 "${dc[@]}" --out "$run"
            # slide.json is pretty-printed: top-level keys at two spaces, equal_sharing's at four.
            awk -v pixel="$pixel" -v n=$n '
                /^  "load_n"/ { load = $2 }
                /^  "contact_points"/ { points = $2 }
                /^    "slip_distance_m"/ { dc = $2 }
                /^  "static_coefficient"/ { mu = $2 }
                /^  "friction_drop"/ { drop = $2 }
                /^  "equal_sharing"/ { equal = 1 }
                equal && /^    "static_coefficient"/ { emu = $2 }
                equal && /^    "friction_drop"/ { edrop = $2; equal = 0 }
                /^    "seconds"/ { seconds = $2 }
                END {
                    gsub(/,/, "", load); gsub(/,/, "", points); gsub(/,/, "", dc); gsub(/,/, "", mu)
                    gsub(/,/, "", drop); gsub(/,/, "", emu); gsub(/,/, "", edrop); gsub(/,/, "", seconds)
                    if (dc == "") dc = 0
                    print pixel "," n "," load "," dc "," points "," mu "," drop "," emu "," edrop "," seconds
                }' "$run/slide.json" >>"$csv.part"
        done
    done
done
mv "$csv.part" "$csv"
cargo run --release --quiet --manifest-path "$root/Cargo.toml" --example sharing_convergence -- "$out/$csv" "$figure"
