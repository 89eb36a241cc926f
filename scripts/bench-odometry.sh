#!/usr/bin/env bash
# The odometry as aditd runs it, over a set of simulated drives: for each,
# `adit bench odometry --config session.yaml` (body frame, the lidar's
# extrinsics, the CAN wheels' prior and the accelerometer's gravity) against
# the true body trajectory; then the mean and the worst. One drive is an
# anecdote (docs/decisions/014-judge-map-on-twelve-drives.md): judge on the set.
#
# Usage: scripts/bench-odometry.sh [DRIVE ...]
#   DRIVE = scene:platform:seconds:seed (adit sim's options); without
#   arguments, the twelve drives of scripts/sim-sessions.sh.
# Sessions are shared with scripts/bench-map.sh (build/sessions/bench-map/);
# each run's output goes to build/bench-odometry/NAME.txt.
# ADIT_BUILD_DIR: the build tree whose bin/ runs and which holds those folders (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
use_drives bench-odometry "$@"
printf '%-24s %12s %12s %12s %14s\n' drive ape-rmse-m drift-% median-ms x-real-time
: > "$runs/figures.txt"
for drive in "${drives[@]}"; do
  session=$(sim_session "$drive" "$runs") || exit $?
  name=$(basename "$session")
  "$build/bin/adit" bench odometry --pcap "$session/lidar.pcap" --model VLP-16 --calibration "$session/VLP16.yaml" \
    --config "$session/session.yaml" --truth "$session/truth_body.tum" --baseline none --out "$runs/$name.tum" \
    > "$runs/$name.txt" 2>&1 || { echo "bench-odometry: $drive: adit bench odometry failed ($runs/$name.txt)" >&2; exit 1; }
  # "adit odometry: APE (SE(3)-aligned) rmse 0.019 m, ..."; "... = 0.018 % (path shorter ...)" or "drift 0.033 % and ..."
  # A straight path has no APE: the SE(3) fit of collinear positions leaves the roll about the line free.
  ape=$(awk '/^adit odometry: APE/ {print $6}' "$runs/$name.txt")
  ape=${ape:--}
  drift=$(awk '/^adit odometry: end-to-end/ {for (i = 1; i <= NF; ++i) if ($i == "=") print $(i + 1)}
               /^adit odometry: drift/ {print $4}' "$runs/$name.txt")
  read -r median speed < <(awk '/^adit odometry: median/ {print $4, substr($12, 1, length($12) - 1)}' "$runs/$name.txt")
  printf '%-24s %12s %12s %12s %14s\n' "$name" "$ape" "$drift" "$median" "$speed"
  echo "$ape $drift" >> "$runs/figures.txt"
done
awk '$1 != "-" {a += $1; na += 1; if ($1 > wa) wa = $1} {d += $2; nd += 1; if ($2 > wd) wd = $2}
  END {printf "drift: mean %.3f %%, worst %.3f %% over %d drives; APE: mean %.3f m, worst %.3f m over the %d with one\n",
              d / nd, wd, nd, (na ? a / na : 0), wa, na}' "$runs/figures.txt"
