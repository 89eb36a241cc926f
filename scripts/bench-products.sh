#!/usr/bin/env bash
# The session products against the simulator's truth over a set of drives:
# for each, aditd maps the recording (`aditd --once`), `adit products` writes
# the 3D occupancy and the 2D grid from the session folder, and `adit eval
# grid` scores the grid against the scene rasterised at 5 cm (IoU of free and
# occupied cells, docs/PRODUCTS.md) and `adit eval sections` the widths on the
# cross-sections against the scene cut at the same places; then the mean and
# the worst.
#
# Usage: scripts/bench-products.sh [DRIVE ...]
#   DRIVE = scene:platform:seconds:seed (adit sim's options); without arguments
#   the six drives below (mine, drift, building).
# ADIT_PRODUCTS_ARGS: extra options for `adit products`, e.g. "--grid-resolution 0.01".
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
default_drives=(mine:robot:60:1 mine:robot:60:2 mine:robot:60:3 drift:robot:90:2 building:robot:60:1 building:robot:60:2)
use_drives bench-products "$@"
[ $# -gt 0 ] || drives=("${default_drives[@]}")
printf '%-22s %8s %8s %8s %8s %11s %9s %9s %7s %9s %9s\n' drive iou-free iou-occ occ-1cell known points-kB bt-kB grid-kB cpu-s width-rms width-max
results=()
for drive in "${drives[@]}"; do
  session=$(sim_session "$drive" "$runs") || exit $?
  name=$(basename "$session")
  work="$runs/$name"
  folder=$(map_once "$session" "$work") || exit 1  # aditd's map once per drive; products and scores every run
  # shellcheck disable=SC2086
  "$build/bin/adit" products "$folder" --out "$work/products" ${ADIT_PRODUCTS_ARGS:-} > "$work/products.txt" ||
    { echo "bench-products: $drive: adit products failed ($work/products.txt)" >&2; exit 1; }
  "$build/bin/adit" eval grid --grid "$work/products/grid.yaml" --scene "$session/scene.ply" \
    --ref "$session/truth_body.tum" --est "$folder/map_trajectory.tum" --json > "$work/grid.json" ||
    { echo "bench-products: $drive: adit eval grid failed" >&2; exit 1; }
  "$build/bin/adit" eval sections --sections "$work/products/sections/sections.csv" --scene "$session/scene.ply" \
    --ref "$session/truth_body.tum" --est "$folder/map_trajectory.tum" --json > "$work/sections.json" ||
    { echo "bench-products: $drive: adit eval sections failed" >&2; exit 1; }
  row=$(python3 - "$work/grid.json" "$work/products/products.json" "$work/sections.json" <<'PY'
import json, sys
g = json.load(open(sys.argv[1])); p = json.load(open(sys.argv[2])); s = json.load(open(sys.argv[3]))
b = p["bytes"]; w = s["width"]
print(f'{g["iou_free"]:.4f} {g["iou_occupied"]:.4f} {g["iou_occupied_within_1_cell"]:.4f} {g["iou_known"]:.4f} '
      f'{b["points"]/1000:.1f} {b["octree_bt"]/1000:.1f} {b["grid"]/1000:.1f} {p["cpu_s"]:.2f} '
      f'{w["rms_m"] if w["n"] else float("nan"):.4f} {w["worst_m"] if w["n"] else float("nan"):.4f} {w["n"]}')
PY
)
  read -r f o o1 k pb bt gb cpu wr wm wn <<< "$row"
  printf '%-22s %8s %8s %8s %8s %11s %9s %9s %7s %9s %9s\n' "$name" "$f" "$o" "$o1" "$k" "$pb" "$bt" "$gb" "$cpu" "$wr" "$wm"
  results+=("$row")
done
# Widths: the rms over every section of every drive (sum of squares weighted by count), the worst of all.
printf '%s\n' "${results[@]}" | awk '
  { for (i = 1; i <= 4; i++) { s[i] += $i; if (NR == 1 || $i < w[i]) w[i] = $i } n++
    if ($11 > 0) { ss += $9 * $9 * $11; sn += $11; if ($10 > wmax) wmax = $10 } }
  END { printf "mean  iou-free %.4f  iou-occ %.4f  occ-1cell %.4f  known %.4f over %d drives\n", s[1]/n, s[2]/n, s[3]/n, s[4]/n, n
        printf "worst iou-free %.4f  iou-occ %.4f  occ-1cell %.4f  known %.4f\n", w[1], w[2], w[3], w[4]
        if (sn > 0) printf "widths: rms %.4f m over %d sections, worst %.4f m\n", sqrt(ss / sn), sn, wmax }'
