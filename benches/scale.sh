#!/usr/bin/env bash
# Scale: one periodic contact solve on an N×N grid (default 4096, then 8192) of the paper's
# surface window (31.13 µm, silicon ball roughness on a 1.5 mm sphere), at 10 mN, cold.
# Prints the solver's time, iterations and FFT pairs per iteration (contact.json) and the peak
# memory (GNU time).
#   bash benches/scale.sh [N...]
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(4096 8192)
for n in "${sizes[@]}"; do
  ./target/release/asperity topo generate --size 31.13e-6 --grid "$n" --hurst 0.8 --rms 22e-9 \
    --rolloff 5e-6 --sphere-radius 1.5e-3 --seed 1 "$work/surface-$n.npy" >/dev/null
  /usr/bin/time -v ./target/release/asperity contact "$work/surface-$n.npy" --size 31.13e-6 \
    --load 1e-2 --out "$work/contact-$n" 2> "$work/time-$n.txt"
  python3 - "$work/contact-$n/contact.json" "$work/time-$n.txt" "$n" <<'PY'
import json, re, sys
c = json.load(open(sys.argv[1]))["loads"][0]
t = open(sys.argv[2]).read()
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 2**20
wall = re.search(r"Elapsed \(wall clock\) time.*: (\S+)", t).group(1)
pairs = c["operator_applications"] / c["iterations"]
print(f"{sys.argv[3]}²: solve {c['seconds']:.1f} s, {c['iterations']} iterations, {pairs:.2f} FFT pairs/iteration, "
      f"{c['contact_points']} contact points; whole command {wall} (read, solve, write); peak memory {rss:.2f} GiB")
PY
  rm -rf "$work/surface-$n.npy" "$work/contact-$n"
done
