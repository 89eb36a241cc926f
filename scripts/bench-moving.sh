#!/usr/bin/env bash
# Moving objects out of the map against the simulator's truth over a set of
# drives with people walking (adit sim --people N): for each, aditd maps the
# recording (`aditd --once`), `adit products` removes what the recording's
# scans saw through (docs/PRODUCTS.md "Moving objects") and `adit eval moving`
# scores the removed and the kept points against the people's tracks
# (truth_people.csv); then the mean and the worst.
#
# Usage: scripts/bench-moving.sh [DRIVE ...]
#   DRIVE = scene:platform:seconds:seed (adit sim's options); without arguments
#   the seven drives below (mine, building, drift).
# ADIT_PEOPLE: walkers per drive (default 5). ADIT_PRODUCTS_ARGS: extra options for `adit products`.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh  # build, aditd_config
people=${ADIT_PEOPLE:-5}
drives=("$@")
[ ${#drives[@]} -gt 0 ] || drives=(mine:robot:60:1 mine:robot:60:2 mine:robot:60:3 building:robot:60:1
                                   building:robot:60:2 drift:robot:90:2 drift:robot:90:3)
runs=$build/bench-moving
mkdir -p "$runs"
printf '%-26s %9s %9s %8s %10s %9s %8s %8s %8s\n' drive people removed people-% static static-rm static-% cpu-s all-cpu-s
results=()
for drive in "${drives[@]}"; do
  IFS=: read -r scene platform seconds seed <<< "$drive"
  name="$scene-$platform-$seconds-s$seed-p$people"
  session="$build/sessions/bench-moving/$name"
  if [ ! -f "$session/truth_people.csv" ]; then
    mkdir -p "$session"
    "$build/bin/adit" sim --scene "$scene" --platform "$platform" --sensor VLP-16 --duration "$seconds" --seed "$seed" \
      --people "$people" --out "$session" > "$runs/$name-sim.log" 2>&1 || { echo "$drive: adit sim failed" >&2; exit 1; }
  fi
  work="$runs/$name"
  folder=$(map_once "$session" "$work") || exit 1  # aditd's map once per drive; products and scores every run
  rm -rf "$work/products"  # no file of an earlier run is scored
  # shellcheck disable=SC2086
  "$build/bin/adit" products "$folder" --out "$work/products" ${ADIT_PRODUCTS_ARGS:-} > "$work/products.txt" ||
    { echo "bench-moving: $drive: adit products failed ($work/products.txt)" >&2; exit 1; }
  if [ ! -f "$work/products/moving_points.ply" ]; then  # turned off (--keep-moving): the products' CPU alone
    cpu=$(python3 -c 'import json, sys; print(f"{json.load(open(sys.argv[1]))[\"cpu_s\"]:.2f}")' "$work/products/products.json")
    printf '%-26s %9s %9s %8s %10s %9s %8s %8s %8s\n' "$name" - - - - - - - "$cpu"
    continue
  fi
  static=$(ls "$work"/products/map_static.* | head -1)
  "$build/bin/adit" eval moving --kept "$static" --removed "$work/products/moving_points.ply" \
    --people "$session/truth_people.csv" --ref "$session/truth_body.tum" --est "$folder/map_trajectory.tum" --json \
    > "$work/moving.json" || { echo "bench-moving: $drive: adit eval moving failed" >&2; exit 1; }
  row=$(python3 - "$work/moving.json" "$work/products/products.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1])); p = json.load(open(sys.argv[2]))
print(f'{m["people_points"]} {m["people_removed"]} {100*m["people_removed_fraction"]:.2f} {m["static_points"]} '
      f'{m["static_removed"]} {100*m["static_removed_fraction"]:.3f} {p["moving_objects"]["cpu_s"]:.2f} {p["cpu_s"]:.2f}')
PY
)
  read -r pp pr pf sp sr sf mc ac <<< "$row"
  printf '%-26s %9s %9s %8s %10s %9s %8s %8s %8s\n' "$name" "$pp" "$pr" "$pf" "$sp" "$sr" "$sf" "$mc" "$ac"
  results+=("$row")
done
[ ${#results[@]} -gt 0 ] || exit 0
printf '%s\n' "${results[@]}" | awk '
  { pf += $3; sf += $6; mc += $7; n++
    if (n == 1 || $3 < wp) wp = $3
    if (n == 1 || $6 > ws) ws = $6
    if (n == 1 || $7 > wc) wc = $7 }
  END { printf "mean  people removed %.2f %%  static removed %.3f %%  moving-objects CPU %.2f s over %d drives\n", pf/n, sf/n, mc/n, n
        printf "worst people removed %.2f %%  static removed %.3f %%  moving-objects CPU %.2f s\n", wp, ws, wc }'
