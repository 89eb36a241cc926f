#!/usr/bin/env bash
# Map accuracy over a set of simulated drives: for each, aditd maps the whole
# recording (`aditd --once`, as fast as it can) and `adit eval map` counts the
# map points within 5 cm of the true scene; then the mean and the worst.
#
# One drive is not enough to judge a change: its figure moves by 10-40 points
# with a tenth of a degree of tilt, and a change that helps one seed can cost
# another as much (docs/decisions/014-judge-map-on-twelve-drives.md). Judge on the set.
#
# Usage: scripts/bench-map.sh [DRIVE ...]
#   DRIVE = scene:platform:seconds:seed[:OPTIONS], e.g. mine:robot:60:3 or mine:drone:30:1:--sensor=Mid-360
#   (adit sim's options; OPTIONS comma-separated, scripts/sim-sessions.sh);
#   without arguments, the twelve drives of docs/decisions/014-judge-map-on-twelve-drives.md (about 3 minutes on 2 cores).
# Sessions are made once under build/sessions/bench-map/; each run's files go to build/bench-map/.
# ADIT_BUILD_DIR: the build tree whose bin/ runs and which holds those folders (default: build).
# ADIT_BENCH_YAML: lines appended to each run's aditd.yaml, e.g. $'map:\n  loops_move_map: true'.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
use_drives bench-map "$@"
sum=0
worst=100
count=0
printf '%-24s %10s %10s %9s\n' drive points within-5cm map-tilt
for drive in "${drives[@]}"; do
  session=$(sim_session "$drive" "$runs") || exit $?
  name=$(basename "$session")
  work="$runs/$name"
  rm -rf "$work"  # mapped again on every run: the map is what this scores
  folder=$(map_once "$session" "$work" "${ADIT_BENCH_YAML:-}") || exit 1
  "$build/bin/adit" eval map --map "$folder/map.ply" --scene "$session/scene.ply" --ref "$session/truth_body.tum" \
    --est "$folder/trajectory.tum" --within 0.05 > "$work/eval.txt" ||
    { echo "bench-map: $drive: adit eval map failed ($work/eval.txt)" >&2; exit 1; }
  # "within 0.050 m    96.92 % (366992 points)"
  read -r within points < <(awk '/^within/ {print $4, substr($6, 2)}' "$work/eval.txt")
  # "map tilt          0.751° (...)": the map's own z from the vertical, which the placement removed
  tilt=$(awk '/^map tilt/ {print $3}' "$work/eval.txt")
  printf '%-24s %10s %9s%% %9s\n' "$name" "$points" "$within" "$tilt"
  sum=$(awk -v a="$sum" -v b="$within" 'BEGIN {print a + b}')
  worst=$(awk -v a="$worst" -v b="$within" 'BEGIN {print (b < a) ? b : a}')
  count=$((count + 1))
done
awk -v s="$sum" -v n="$count" -v w="$worst" 'BEGIN {printf "mean %.2f %% within 5 cm over %d drives, worst %.2f %%\n", s / n, n, w}'
