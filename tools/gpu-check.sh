#!/usr/bin/env bash
# The GPU backend's checks on a machine with an NVIDIA GPU and no network: the GPU
# tests, the CPU-against-GPU benchmark on the same host, and the default study on both devices.
#
#   tools/gpu-check.sh --build DIR   here, with Rust: build with --features gpu and pack the
#                                    stripped binaries into DIR/bins.tar.gz
#   tools/gpu-check.sh DIR [SIZES]   there: unpack DIR/bins.tar.gz and run the checks; results
#                                    in $OUT (or target/gpu-check): gpu-check.md and logs
#
# SIZES (default "1024 1500 4096 8192 16384 32768"): grids of the benchmark; the CPU solves up
# to 16384², the GPU alone beyond. The CUDA driver, cuFFT and NVRTC come with the machine's
# driver and toolkit; where the loader does not find them, their folders are looked up.
set -uo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--build" ]; then
  dir=${2:?--build DIR}
  cargo build --release --features gpu --bin asperity --example gpu_bench || exit 1
  tests=$(cargo test --release --features gpu --test gpu --no-run --message-format=json 2>/dev/null |
    python3 -c 'import json,sys
for l in sys.stdin:
    m = json.loads(l)
    if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "gpu" and m.get("executable"): print(m["executable"])')
  [ -n "$tests" ] || { echo "gpu-check: the GPU tests did not build" >&2; exit 1; }
  stage=$(mktemp -d)
  cp target/release/asperity target/release/examples/gpu_bench "$stage/"
  cp "$tests" "$stage/gpu-tests"
  strip "$stage"/*
  mkdir -p "$dir"
  tar -C "$stage" -czf "$dir/bins.tar.gz" asperity gpu_bench gpu-tests
  # The tests run the binary by the path it was built at.
  echo "$PWD/target/release/asperity" >"$dir/bin-path"
  rm -rf "$stage"
  ls -l "$dir/bins.tar.gz"
  exit 0
fi

dir=${1:?usage: tools/gpu-check.sh DIR [SIZES] (see the header)}
sizes=${2:-1024 1500 4096 8192 16384 32768}
out=${OUT:-target/gpu-check}
mkdir -p "$out"
bin=$(mktemp -d)
tar -C "$bin" -xzf "$dir/bins.tar.gz" || exit 1
built=$(cat "$dir/bin-path")
[ -e "$built" ] || { mkdir -p "$(dirname "$built")" && cp "$bin/asperity" "$built"; }
report=$out/gpu-check.md
log() { echo "$@" | tee -a "$report"; }

# The CUDA libraries: the loader's, else the toolkit's and the Python wheels' folders.
for lib in libcufft.so libnvrtc.so; do
  if ! ldconfig -p | grep -q "$lib"; then
    found=$(find /usr/local /opt /usr/lib -name "$lib*" 2>/dev/null | head -n 1)
    [ -n "$found" ] && export LD_LIBRARY_PATH="$(dirname "$found")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  fi
done

log "# GPU check, $(date -u '+%Y-%m-%d %H:%M UTC')"
log ""
log "- host: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB; GPU: $(nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>&1)"
log "- $("$bin/asperity" --version)"
log "- LD_LIBRARY_PATH=${LD_LIBRARY_PATH:-}"
log ""

log "## GPU tests"
timeout 300 "$bin/gpu-tests" --test-threads=1 --nocapture >"$out/tests.log" 2>&1
status=$?
grep -E "it, GPU|skipped|test result|panicked|FAILED" "$out/tests.log" | sed 's/^/    /' | tee -a "$report"
[ $status -eq 0 ] || { log "the GPU tests failed (exit $status): see tests.log"; exit 1; }
log ""

log "## Benchmark: the default ball at 10 mN, periodic, tolerance 1e-10, each solve cold"
first=1
bench() {
  for n in "$@"; do
    header=$([ $first -eq 1 ] && echo cat || echo "tail -n +3")
    timeout 400 "$bin/gpu_bench" --cpu-up-to 16384 "$n" 2>>"$out/bench.log" | $header | tee -a "$report"
    first=0
  done
}
# The small grids, the study, then the large grids (the longest, last).
bench $(for n in $sizes; do [ "$n" -le 8192 ] && echo "$n"; done)
log ""

log "## The default study, on the GPU and on the CPU ($(nproc) cores)"
"$bin/asperity" run --print-default >"$out/gpu.toml"
sed -i '/^\[contact\]/a device = "gpu"' "$out/gpu.toml"
study() {
  local name=$1; shift
  local start=$(date +%s.%N)
  timeout 300 "$bin/asperity" run "$@" --out "$bin/$name" >"$out/$name.log" 2>&1
  local status=$? end=$(date +%s.%N)
  local solves=$(python3 -c 'import csv,sys
rows = list(csv.DictReader(open(sys.argv[1])))
law = rows[0]["law"]
print(round(sum(float(r["seconds"]) for r in rows if r["law"] == law), 2))' "$bin/$name/results.csv" 2>/dev/null)
  log "- $name: exit $status, wall $(python3 -c "print(round($end - $start, 1))") s, solves $solves s (sum over the solves)"
  cp "$bin/$name/results.csv" "$out/$name-results.csv" 2>/dev/null
}
study study-gpu "$out/gpu.toml"
study study-cpu
log ""
log "## Benchmark, large grids"
bench $(for n in $sizes; do [ "$n" -gt 8192 ] && echo "$n"; done)
