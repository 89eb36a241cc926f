#!/usr/bin/env bash
# Map accuracy over a set of simulated drives: for each, aditd maps the whole
# recording (`aditd --once`, as fast as it can) and `adit eval map` counts the
# map points within 5 cm of the true scene; then the mean and the worst. The
# map is placed by its first pose (the figure of record) and again by that
# pose's position and heading only (`--align heading`): there it keeps its own
# vertical (levelled by the odometry's gravity, decision 060), and its tilt
# from plumb (printed) counts.
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
sum_plumb=0
worst_plumb=100
count=0
printf '%-24s %10s %10s %9s %10s\n' drive points within-5cm map-tilt own-level
for drive in "${drives[@]}"; do
  session=$(sim_session "$drive" "$runs") || exit $?
  name=$(basename "$session")
  work="$runs/$name"
  rm -rf "$work"  # mapped again on every run: the map is what this scores
  folder=$(map_once "$session" "$work" "${ADIT_BENCH_YAML:-}") || exit 1
  # Placed by the first pose (the figure of record), then by its position and
  # heading only, so the map keeps its own vertical (what a crew without
  # control points gets; docs/decisions/059-graph-keeps-the-first-poses-attitude.md).
  for align in origin heading; do
    "$build/bin/adit" eval map --map "$folder/map.ply" --scene "$session/scene.ply" --ref "$session/truth_body.tum" \
      --est "$folder/trajectory.tum" --align "$align" --within 0.05 > "$work/eval-$align.txt" ||
      { echo "bench-map: $drive: adit eval map --align $align failed ($work/eval-$align.txt)" >&2; exit 1; }
  done
  # "within 0.050 m    96.92 % (366992 points)"
  read -r within points < <(awk '/^within/ {print $4, substr($6, 2)}' "$work/eval-origin.txt")
  plumb=$(awk '/^within/ {print $4}' "$work/eval-heading.txt")
  # "map tilt          0.751° (...)": the map's own z from the vertical, which the origin placement removed
  tilt=$(awk '/^map tilt/ {print $3}' "$work/eval-origin.txt")
  printf '%-24s %10s %9s%% %9s %9s%%\n' "$name" "$points" "$within" "$tilt" "$plumb"
  sum=$(awk -v a="$sum" -v b="$within" 'BEGIN {print a + b}')
  worst=$(awk -v a="$worst" -v b="$within" 'BEGIN {print (b < a) ? b : a}')
  sum_plumb=$(awk -v a="$sum_plumb" -v b="$plumb" 'BEGIN {print a + b}')
  worst_plumb=$(awk -v a="$worst_plumb" -v b="$plumb" 'BEGIN {print (b < a) ? b : a}')
  count=$((count + 1))
done
awk -v s="$sum" -v n="$count" -v w="$worst" 'BEGIN {printf "mean %.2f %% within 5 cm over %d drives, worst %.2f %%\n", s / n, n, w}'
awk -v s="$sum_plumb" -v n="$count" -v w="$worst_plumb" \
  'BEGIN {printf "keeping its own vertical: mean %.2f %%, worst %.2f %%\n", s / n, w}'
