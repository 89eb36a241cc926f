#!/usr/bin/env bash
# Memory of a large prior map (issue #22: "memory for a 100 m x 100 m floor
# prior reported"): the simulated building's bim.ply (a 40 x 25 m floor) laid
# side by side until it covers SIZE x SIZE metres (below), prepared by `adit prior-map
# prepare` as a crew would, then loaded by aditd on a building drive beside the
# same drive without a prior and with the one-floor prior. Reports, for each:
# the prepared prior (points, the size `prepare` prints), the peak resident size
# of `prepare` and of aditd (GNU time's maximum RSS), aditd's odometry p99 and
# whether it anchored, each run at the drive's own pace (the prior is read, indexed and searched whole, and
# once anchored every scan is registered against it too).
#
# Usage: scripts/bench-prior-memory.sh [SIZE_M (100)] [DRIVE (building:robot:60:1)]
# Files go to $build/bench-prior-memory/. ADIT_BUILD_DIR: the build tree (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
size=${1:-100}
drive=${2:-building:robot:60:1}
work="$build/bench-prior-memory"
mkdir -p "$work"
session=$(sim_session "$drive" "$work") || exit $?
adit="$build/bin/adit"

# bim.ply (binary little-endian x y z floats, as adit sim writes it) repeated
# on a grid of its own extent, clipped to SIZE x SIZE metres: the first copy
# where the drive is, the others mirrored (x -> -x), which no rigid motion
# lays on the drive, so the floor the drive saw is in the prior once.
python3 - "$session/bim.ply" "$work/bim-${size}m.ply" "$size" <<'PY'
import struct, sys
src, dst, size = sys.argv[1], sys.argv[2], float(sys.argv[3])
data = open(src, "rb").read()
end = data.index(b"end_header\n") + len(b"end_header\n")
header = data[:end].decode()
if "property float x\nproperty float y\nproperty float z\nend_header" not in header or "binary_little_endian" not in header:
    sys.exit(f"{src}: expected a binary little-endian PLY of float x y z only")
pts = list(struct.iter_unpack("<fff", data[end:]))
x0, y0 = min(p[0] for p in pts), min(p[1] for p in pts)
w, h = max(p[0] for p in pts) - x0, max(p[1] for p in pts) - y0
out = []
for i in range(int(size // w) + 1):
    for j in range(int(size // h) + 1):
        mirror = i > 0 or j > 0
        for x, y, z in pts:
            tx, ty = (w - (x - x0) if mirror else x - x0) + i * w, y - y0 + j * h
            if tx <= size and ty <= size:
                out.append(struct.pack("<fff", tx, ty, z))
with open(dst, "wb") as f:
    f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(out)}\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n".encode())
    f.write(b"".join(out))
print(f"{dst}: {len(out)} points, {size:.0f} x {size:.0f} m from a {w:.1f} x {h:.1f} m floor of {len(pts)}")
PY

peak_mb() { awk '{printf "%.1f", $1 / 1024}' "$1"; }  # GNU time's %M (KiB)
printf '%-10s %10s %12s %14s %12s %14s %10s\n' prior points prepared_mb prepare_peak_mb aditd_peak_mb odometry_p99_ms anchored
for prior in none one-floor "${size}m"; do
  case $prior in
    none) yaml="" ;;
    one-floor) in="$session/bim.ply" ;;
    *) in="$work/bim-${size}m.ply" ;;
  esac
  run="$work/$prior"
  rm -rf "$run"
  mkdir -p "$run"
  points=- prepared=- prepare_peak=-
  if [ "$prior" != none ]; then
    /usr/bin/time -f '%M' -o "$run/prepare.rss" "$adit" prior-map prepare "$in" --out "$run/prior" > "$run/prepare.txt"
    # "points: 3123 read, 2980 kept at 0.10 m (...)" and "memory: 6.8 MB; prepared in 1.2 s"
    points=$(awk '/^points:/ {print $4}' "$run/prepare.txt")
    prepared=$(awk '/^memory:/ {print $2}' "$run/prepare.txt")
    prepare_peak=$(peak_mb "$run/prepare.rss")
    yaml=$(printf 'prior_map:\n  dir: %s' "$run/prior")
  fi
  aditd_config "$session" "$run" 1 > "$run/aditd.yaml"  # at the drive's own pace, as a payload: the search keeps up
  printf 'session:\n  products: false\n' >> "$run/aditd.yaml"
  [ -z "$yaml" ] || printf '%s\n' "$yaml" >> "$run/aditd.yaml"
  /usr/bin/time -f '%M' -o "$run/aditd.rss" "$build/bin/aditd" --config "$run/aditd.yaml" --once > "$run/aditd.log" 2>&1 ||
    { echo "bench-prior-memory: aditd failed ($run/aditd.log)" >&2; exit 1; }
  summary=$(ls -d "$run"/state/sessions/*/ | head -1)summary.json
  read -r p99 anchored < <(python3 -c 'import json, sys; s = json.load(open(sys.argv[1]))
print("%.2f" % s["timing"]["odometry_ms_p99"], s["prior_map"].get("anchored", "-"))' "$summary")
  printf '%-10s %10s %12s %14s %12s %14s %10s\n' "$prior" "$points" "$prepared" "$prepare_peak" \
    "$(peak_mb "$run/aditd.rss")" "$p99" "$anchored"
done
