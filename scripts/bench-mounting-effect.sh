#!/usr/bin/env bash
# What the mounting costs the map: after scripts/bench-mounting.sh, each of
# its drives is mapped again with the wheels and the IMU fused, under three
# configs: the nominal one (rotation 0, lever arm 0), the calibrated one (the
# lines `adit calibrate-mounting` printed) and the simulated truth. The
# sensor's trajectory (aditd's body poses through each config's extrinsics)
# is compared with the simulated sensor's (`adit eval traj --align se3`),
# and the map with the scene (`adit eval map`, points within 5 cm, placed by
# the sensor's first pose).
#
# Usage: scripts/bench-mounting-effect.sh [NAME ...]   (folders under build/bench-mounting/; default: all)
# ADIT_BUILD_DIR: the build tree whose bin/ runs (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
runs=$build/bench-mounting
names=("$@")
[ ${#names[@]} -gt 0 ] || mapfile -t names < <(cd "$runs" && ls -d */ | tr -d /)

# sensor_tum BODY_TUM XYZ RPY_DEG > SENSOR_TUM: body poses times the extrinsics.
sensor_tum() {
  python3 - "$1" "$2" "$3" <<'EOF'
import math, sys
def q_mul(a, b):
    aw, ax, ay, az = a; bw, bx, by, bz = b
    return (aw*bw - ax*bx - ay*by - az*bz, aw*bx + ax*bw + ay*bz - az*by,
            aw*by - ax*bz + ay*bw + az*bx, aw*bz + ax*by - ay*bx + az*bw)
def rotate(q, v):
    w, x, y, z = q
    return q_mul(q_mul(q, (0.0, *v)), (w, -x, -y, -z))[1:]
def axis(angle, i):
    v = [0.0, 0.0, 0.0]; v[i] = math.sin(angle / 2)
    return (math.cos(angle / 2), *v)
xyz = [float(v) for v in sys.argv[2].split(",")]
r, p, y = (math.radians(float(v)) for v in sys.argv[3].split(","))
e = q_mul(q_mul(axis(y, 2), axis(p, 1)), axis(r, 0))
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) != 8 or f[0].startswith("#"):
        continue
    t = [float(v) for v in f[1:4]]
    q = (float(f[7]), float(f[4]), float(f[5]), float(f[6]))
    d = rotate(q, xyz)
    s = q_mul(q, e)
    print(f"{f[0]} {t[0] + d[0]:.6f} {t[1] + d[1]:.6f} {t[2] + d[2]:.6f} {s[1]:.9f} {s[2]:.9f} {s[3]:.9f} {s[0]:.9f}")
EOF
}

printf '%-28s %-11s %10s %10s\n' drive config ape_cm within5cm
for name in "${names[@]}"; do
  work=$runs/$name
  session=$work/session
  [ -f "$work/calibration.txt" ] || { echo "$name: run scripts/bench-mounting.sh first" >&2; exit 1; }
  true_xyz=$(awk '/^  extrinsics:/ {f = 1} f && /xyz_m:/ {gsub(/[\[\] ]/, ""); sub(/xyz_m:/, ""); print; exit}' "$session/session.yaml")
  true_rpy=$(awk '/^  extrinsics:/ {f = 1} f && /rpy_deg:/ {gsub(/[\[\] ]/, ""); sub(/rpy_deg:/, ""); print; exit}' "$session/session.yaml")
  cal_xyz=$(awk '/^    xyz_m:/ {gsub(/[\[\] ]/, ""); sub(/xyz_m:/, ""); print}' "$work/calibration.txt")
  cal_rpy=$(awk '/^    rpy_deg:/ {gsub(/[\[\] ]/, ""); sub(/rpy_deg:/, ""); print}' "$work/calibration.txt")
  for config in nominal:0,0,0.45:0,0,0 calibrated:$cal_xyz:$cal_rpy truth:$true_xyz:$true_rpy; do
    IFS=: read -r label xyz rpy <<< "$config"
    out=$work/effect-$label
    rm -rf "$out"
    mkdir -p "$out"
    aditd_config "$session" "$out" | python3 -c '
import re, sys
s = sys.stdin.read()
s = re.sub(r"extrinsics:\n    xyz_m: \[[^\]]*\]\n    rpy_deg: \[[^\]]*\]",
           "extrinsics:\n    xyz_m: [" + sys.argv[1] + "]\n    rpy_deg: [" + sys.argv[2] + "]", s)
sys.stdout.write(s)' "$xyz" "$rpy" > "$out/aditd.yaml"
    printf 'session:\n  products: false\n' >> "$out/aditd.yaml"
    "$build/bin/aditd" --config "$out/aditd.yaml" --once > "$out/aditd.log" 2>&1 ||
      { echo "$name $label: aditd failed ($out/aditd.log)" >&2; exit 1; }
    folder=$(ls -d "$out"/state/sessions/*/ | head -1)
    sensor_tum "$folder/trajectory.tum" "$xyz" "$rpy" > "$out/sensor.tum"
    ape=$("$build/bin/adit" eval traj --ref "$session/truth_sensor.tum" --est "$out/sensor.tum" --align se3 |
          awk '/^APE translation/ {print 100 * $5}')
    "$build/bin/adit" eval map --map "$folder/map.ply" --scene "$session/scene.ply" --ref "$session/truth_body.tum" \
      --est "$folder/trajectory.tum" --within 0.05 > "$out/eval.txt" 2>&1 || true
    within=$(awk '/^within/ {print $4}' "$out/eval.txt")
    printf '%-28s %-11s %10.2f %9s%%\n' "$name" "$label" "$ape" "${within:-?}"
  done
done
