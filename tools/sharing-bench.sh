#!/usr/bin/env bash
# The cost of elastic sharing, in one go, on any machine with a copy of the binary
# (no network, no cargo):
#
#   tools/sharing-bench.sh [BINARY] [THREADS] [--quick] [--no-slide]
#
#   BINARY   the asperity binary (default target/release/asperity)
#   THREADS  RAYON_NUM_THREADS for every run (default: all cores)
#   --quick  the studies at --quick scale (and the slide at 256²), to iterate on
#   --no-slide  the two studies only
#
# Runs the embedded default study (`asperity run --print-default`) twice, in a temporary
# folder, with `[model] sharing = ["equal"]` and with `sharing = ["equal", "elastic"]`, and
# prints each one's wall and CPU seconds (GNU time when /usr/bin/time exists, else bash's
# `times`) and their ratio; then one `asperity slide` of the stand-in ball (1500², the
# default study's ball-1 roughness without its wafer, periodic) at 100 mN, mu_s 0.6, mu_d 0.4,
# d_c 2 nm (slide's default), with its solver's work from slide.json. The temporary folder is removed at the end.
set -euo pipefail

binary=target/release/asperity
threads=
quick=
slide=1
for arg in "$@"; do
  case "$arg" in
    --quick) quick=--quick ;;
    --no-slide) slide= ;;
    --*) echo "sharing-bench: unknown option $arg" >&2; exit 2 ;;
    *)
      if [ -z "${seen_binary:-}" ]; then binary=$arg; seen_binary=1; else threads=$arg; fi ;;
  esac
done
[ -x "$binary" ] || { echo "sharing-bench: $binary is not an executable" >&2; exit 2; }
binary=$(cd "$(dirname "$binary")" && pwd)/$(basename "$binary")
if [ -n "$threads" ]; then
  [[ "$threads" =~ ^[1-9][0-9]*$ ]] || { echo "sharing-bench: THREADS must be a positive integer, not $threads" >&2; exit 2; }
  export RAYON_NUM_THREADS=$threads
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

# wall and CPU seconds of a command, into the named variables
timed() {
  local wall_var=$1 cpu_var=$2
  shift 2
  local start end
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -f '%e %U %S' -o time.txt "$@" >log.txt 2>&1 || { cat log.txt >&2; return 1; }
    read -r w u s <time.txt
    printf -v "$wall_var" '%s' "$w"
    printf -v "$cpu_var" '%s' "$(awk -v u="$u" -v s="$s" 'BEGIN { printf "%.2f", u + s }')"
  else
    start=$(date +%s.%N)
    "$@" >log.txt 2>&1 || { cat log.txt >&2; return 1; }
    end=$(date +%s.%N)
    printf -v "$wall_var" '%s' "$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')"
    printf -v "$cpu_var" '%s' "n/a"
  fi
}

"$binary" run --print-default >default.toml
grep -q '^sharing = ' default.toml || { echo "sharing-bench: no 'sharing = ' line in the default study" >&2; exit 1; }
sed 's/^sharing = .*/sharing = ["equal"]/' default.toml >equal.toml
sed 's/^sharing = .*/sharing = ["equal", "elastic"]/' default.toml >both.toml

echo "binary $binary; RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-all} of $(nproc) cores; ${quick:-full size}; $(date -u '+%Y-%m-%d %H:%M UTC')"
timed equal_wall equal_cpu "$binary" run equal.toml --out equal $quick
echo "study, sharing = [\"equal\"]:            ${equal_wall} s wall, ${equal_cpu} s CPU"
timed both_wall both_cpu "$binary" run both.toml --out both $quick
echo "study, sharing = [\"equal\", \"elastic\"]: ${both_wall} s wall, ${both_cpu} s CPU"
awk -v a="$both_wall" -v b="$equal_wall" 'BEGIN { printf "ratio (both / equal), wall: %.2f\n", a / b }'

[ -n "$slide" ] || exit 0
grid=1500
[ -z "$quick" ] || grid=256
"$binary" topo generate --size 31.13um --grid "$grid" --hurst 0.8 --rms 21nm --rolloff 7um --cutoff 0.25um \
  --sphere-radius 1.5mm --seed 1 ball.npy >/dev/null
timed slide_wall slide_cpu "$binary" slide ball.npy --size 31.13um --load 100mN --mu-s 0.6 --mu-d 0.4 --out slide
work_line=$(python3 - slide/slide.json <<'PY' 2>/dev/null || true
import json, sys
s = json.load(open(sys.argv[1]))
w = s.get("work", {})
print(", ".join(f"{k} {v}" for k, v in w.items()) + f"; friction drop {s['friction_drop']:.7f}")
PY
)
echo "slide ${grid}², 100 mN: ${slide_wall} s wall, ${slide_cpu} s CPU${work_line:+; $work_line}"
