#!/usr/bin/env bash
# Runs every libFuzzer target in BUILD_DIR/bin for SECONDS each, seeded from
# tests/fuzz/<target>.seeds: one path or glob per line, relative to the project
# root; "shared/..." is read from ../shared/data (skipped when absent); a
# "pcap:" prefix cuts a capture into one seed per UDP payload (seeds_from_pcap).
# Crashes are kept in fuzz-artifacts/ and fail the run.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:?usage: scripts/fuzz.sh BUILD_DIR [SECONDS]}
seconds=${2:-15}
# A fixed libFuzzer seed makes CI reproducible: the same mutations every run.
# Set ADIT_FUZZ_SEED=0 (random) or another number to explore further by hand.
fuzz_seed=${ADIT_FUZZ_SEED:-1}
shared=${ADIT_SHARED_DATA:-../shared/data}
mkdir -p fuzz-artifacts

shopt -s nullglob
targets=("$build_dir"/bin/fuzz_*)
if [ ${#targets[@]} -eq 0 ]; then
  echo "fuzz: no fuzz targets built in $build_dir"
  exit 0
fi
for target in "${targets[@]}"; do
  name=$(basename "$target")
  corpus=$(mktemp -d)
  seeds_file="tests/fuzz/$name.seeds"
  if [ -f "$seeds_file" ]; then
    while IFS= read -r pattern; do
      [ -z "$pattern" ] || [ "${pattern#\#}" != "$pattern" ] && continue
      split=false
      case "$pattern" in pcap:*) split=true; pattern=${pattern#pcap:} ;; esac
      case "$pattern" in shared/*) pattern="$shared/${pattern#shared/}" ;; esac
      for seed in $pattern; do
        [ -f "$seed" ] || continue
        if $split; then "$build_dir/bin/seeds_from_pcap" "$corpus" "$seed" >/dev/null; else cp "$seed" "$corpus/"; fi
      done
    done < "$seeds_file"
  fi
  echo "fuzz: $name for ${seconds}s with $(ls "$corpus" | wc -l) seeds"
  "$target" -seed="$fuzz_seed" -max_total_time="$seconds" -rss_limit_mb=2048 -artifact_prefix=fuzz-artifacts/"$name"- \
    -print_final_stats=1 "$corpus" 2>&1 | tail -n 12
  rm -rf "$corpus"
done
