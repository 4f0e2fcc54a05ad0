#!/usr/bin/env bash
# Seed the fuzzing corpora (fuzz/corpus/TARGET/, generated, never committed) from tests/data: each
# file goes to the target of the format asperity reads it as (`asperity topo info`, as a user's
# file is told; a bare array with a made-up size, a file of no height channel by its first;
# a gzipped file inflated), every file to `detect`, every zip to `zip`.
# Files no format reads (corrupted on purpose) seed `detect` only. Needs the release CLI (built
# here when absent).
set -euo pipefail
cd "$(dirname "$0")/.."

cli=target/release/asperity
[ -x "$cli" ] || cargo build --release --bin asperity
corpus=fuzz/corpus
mkdir -p "$corpus/detect" "$corpus/zip"

format_of() {
  { "$cli" topo info --json "$1" 2>/dev/null || "$cli" topo info --json --size 1um "$1" 2>/dev/null ||
    "$cli" topo info --json --channel 0 "$1" 2>/dev/null; } |
    sed -n 's/^  "format": "\(.*\)",$/\1/p' || true
}

for file in tests/data/*; do
  case $file in */README.md | */manifest.json) continue ;; esac
  name=$(basename "$file")
  cp "$file" "$corpus/detect/$name"
  [ "$(head -c 2 "$file" | tr -d '\0')" = PK ] && cp "$file" "$corpus/zip/$name"
  format=$(format_of "$file")
  if [ -n "$format" ]; then
    mkdir -p "$corpus/$format"
    # A format's target reads the format itself: a gzipped sample seeds it inflated.
    case $name in
      *.gz) gunzip -c "$file" >"$corpus/$format/${name%.gz}" ;;
      *) cp "$file" "$corpus/$format/$name" ;;
    esac
  fi
done

# A format without a seed is fuzzed from nothing: say so.
for target in fuzz/fuzz_targets/*.rs; do
  target=$(basename "$target" .rs)
  [ -n "$(ls -A "$corpus/$target" 2>/dev/null)" ] || echo "fuzz/seed.sh: no seed file for $target in tests/data" >&2
done
exit 0
