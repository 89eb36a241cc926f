#!/usr/bin/env bash
# The LiDAR's mounting on a wheeled robot, found from drives: for each, the
# simulator mounts the sensor turned by ROLL/PITCH/YAW (and 0.20 m ahead of
# the axle), aditd maps the drive with the LiDAR alone under the crew's
# nominal config (rotation 0, lever arm 0, height 0.45 m as taped), and
# `adit calibrate-mounting` fits the mounting from aditd's trajectory, the
# wheels and the floor in the capture (the body's origin is the axle,
# 0.1651 m above the floor); the errors against the simulated mounting, then
# the mean and worst. ADIT_MOUNTING_ARGS: more options for calibrate-mounting
# (e.g. --no-floor: roll and pitch from the turns alone).
#
# Usage: scripts/bench-mounting.sh [DRIVE ...]
#   DRIVE = scene:seconds:seed:ROLL/PITCH/YAW (degrees), e.g. building:120:1:2/-4/3;
#   without arguments, the nine drives below (about 4 minutes on 2 cores).
# Files go to build/bench-mounting/; each drive is simulated and mapped once and reused (delete its folder to
# map it again).
# ADIT_BUILD_DIR: the build tree whose bin/ runs (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
runs=$build/bench-mounting
mkdir -p "$runs"
drives=("$@")
[ ${#drives[@]} -gt 0 ] || drives=(building:120:1:2/-4/3 building:120:2:2/-4/3 building:120:3:2/-4/3
                                   building:120:1:-3/1.5/-6 building:120:2:-3/1.5/-6 building:120:3:-3/1.5/-6
                                   mine:120:1:2/-4/3 mine:120:2:-3/1.5/-6 mine:120:3:1/1/10)
printf '%-28s %7s %7s %7s %7s %7s %7s %8s %8s\n' drive roll° pitch° yaw° x_mm y_mm z_mm windows outliers
results=$runs/results.txt
: > "$results"
for drive in "${drives[@]}"; do
  IFS=: read -r scene seconds seed angles <<< "$drive"
  IFS=/ read -r roll pitch yaw <<< "$angles"
  [ -n "$yaw" ] || { echo "$drive: expected scene:seconds:seed:ROLL/PITCH/YAW" >&2; exit 2; }
  name="$scene-$seconds-s$seed-$roll-$pitch-$yaw"
  work=$runs/$name
  session=$work/session
  # Simulated and mapped once, reused while $work/mapped exists (the fit is what this scores).
  if [ ! -f "$work/mapped" ]; then
    rm -rf "$work"
    mkdir -p "$work"
    "$build/bin/adit" sim --scene "$scene" --platform robot --sensor VLP-16 --duration "$seconds" --seed "$seed" \
      --mount-rpy-deg "$roll" "$pitch" "$yaw" --out "$session" > "$work/sim.log" 2>&1 ||
      { echo "$drive: adit sim failed ($work/sim.log)" >&2; exit 1; }
    # The nominal config, mapped with the LiDAR alone: wheels and IMU off
    # (both would be fused through the mounting being calibrated).
    aditd_config "$session" "$work" | python3 -c '
import re, sys
s = sys.stdin.read()
s = re.sub(r"extrinsics:\n    xyz_m: \[[^\]]*\]\n    rpy_deg: \[[^\]]*\]",
           "extrinsics:\n    xyz_m: [0, 0, 0.45]\n    rpy_deg: [0, 0, 0]", s)
s = s.replace("wheel_odometry:\n  enabled: true", "wheel_odometry:\n  enabled: false")
s = s.replace("imu:\n  enabled: true", "imu:\n  enabled: false")
sys.stdout.write(s)' > "$work/aditd.yaml"
    printf 'session:\n  products: false\n' >> "$work/aditd.yaml"
    "$build/bin/aditd" --config "$work/aditd.yaml" --once > "$work/aditd.log" 2>&1 ||
      { echo "$drive: aditd failed ($work/aditd.log)" >&2; exit 1; }
    touch "$work/mapped"
  fi
  folder=$(ls -d "$work"/state/sessions/*/ | head -1)
  # shellcheck disable=SC2086
  "$build/bin/adit" calibrate-mounting --config "$work/aditd.yaml" --trajectory "$folder/trajectory.tum" \
    --body-height 0.1651 ${ADIT_MOUNTING_ARGS:-} > "$work/calibration.txt" 2>&1 || true  # exit 1 when a part is unobservable: the table shows it
  grep -q 'rpy_deg:' "$work/calibration.txt" || { echo "$drive: no calibration ($work/calibration.txt)" >&2; exit 1; }
  # The simulated lever arm is the robot template's: x 0.20 m, y 0, z 0.45 m
  # (without the floor, the nominal z is printed back: its error is 0).
  awk -v name="$name" -v r="$roll" -v p="$pitch" -v y="$yaw" '
    /^sensor poses/ { windows = $8; outliers = $(NF - 3) }
    /xyz_m:/ { gsub(/[\[\],]/, " "); x = $2; yy = $3; z = $4 }
    /rpy_deg:/ { gsub(/[\[\],]/, " "); er = $2 - r; ep = $3 - p; ey = $4 - y }
    END { printf "%-28s %7.3f %7.3f %7.3f %7.1f %7.1f %7.1f %8s %8s\n", name, er, ep, ey, 1000 * (x - 0.20), 1000 * yy,
                 1000 * (z - 0.45), windows, outliers }' \
    "$work/calibration.txt" | tee -a "$results"
done
awk '
  function abs(v) { return v < 0 ? -v : v }
  { n++; for (i = 2; i <= 7; i++) { s[i] += abs($i); if (abs($i) > w[i]) w[i] = abs($i) } }
  END { printf "mean |error| over %d drives: roll %.3f°, pitch %.3f°, yaw %.3f°, x %.1f mm, y %.1f mm, z %.1f mm\n", n, s[2] / n, s[3] / n, s[4] / n, s[5] / n, s[6] / n, s[7] / n
        printf "worst:                        roll %.3f°, pitch %.3f°, yaw %.3f°, x %.1f mm, y %.1f mm, z %.1f mm\n", w[2], w[3], w[4], w[5], w[6], w[7] }' "$results"
