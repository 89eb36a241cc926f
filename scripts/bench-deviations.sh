#!/usr/bin/env bash
# As-built against as-designed (issue #22's deviation target: the simulator's
# real differences found with >= 90 % precision and recall at 5 cm), over
# building drives: each mapped by aditd twice, without a prior (the map then
# placed in the prior by `adit prior-map deviations`' own localisation) and
# with the drive's bim.ply as its prior (anchored: the map is written in the
# prior's frame, so `--aligned`); then `adit prior-map deviations
# --truth-scene` scores each map's deviating points against the scene's real
# differences. Prints each run, then the mean and the worst of each column.
#
# Usage: scripts/bench-deviations.sh [DRIVE ...]   (default building:robot:60:1-3 and building:handheld:60:1-3;
#   about 3 minutes a drive on 2 cores: the anchored run maps at the drive's own pace)
# Sessions are simulated once under build/sessions/bench-map/; runs go to build/bench-deviations/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
use_drives bench-deviations "$@"
[ $# -gt 0 ] || drives=(building:robot:60:1 building:robot:60:2 building:robot:60:3
                        building:handheld:60:1 building:handheld:60:2 building:handheld:60:3)
adit="$build/bin/adit"
field() { python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$@"; }

printf '%-24s %-9s %9s %9s %9s %9s %9s\n' drive map anchored_s p_points r_points p_regions r_regions
rows=()
for drive in "${drives[@]}"; do
  session=$(sim_session "$drive" "$runs") || exit $?
  name=$(basename "$session")
  prior="$runs/$name/prior"
  if [ ! -f "$prior/prior_map.bin" ]; then
    mkdir -p "$runs/$name"
    "$adit" prior-map prepare "$session/bim.ply" --out "$prior" > "$runs/$name/prepare.txt"
  fi
  for kind in plain anchored; do
    work="$runs/$name/$kind"
    rm -rf "$work"
    extra="" aligned=()
    if [ "$kind" = anchored ]; then
      extra=$(printf 'prior_map:\n  dir: %s' "$prior")
      aligned=(--aligned)
    fi
    # The anchored run at the drive's own pace, as a payload maps it: replayed as fast as it goes, the odometry
    # runs on while the search does and maps most of the drive before it is anchored (docs/PRIOR-MAP.md).
    folder=$(map_once "$session" "$work" "$extra" "$([ "$kind" = anchored ] && echo 1 || echo 0)") || exit 1
    anchored=$(field "$folder/summary.json" 'j["prior_map"].get("anchored", "-")')
    after=$(field "$folder/summary.json" '"%.1f" % j["prior_map"]["anchored_after_s"] if j["prior_map"].get("anchored") else "-"')
    if [ "$kind" = anchored ] && [ "$anchored" != True ]; then
      printf '%-24s %-9s %9s (never anchored: not scored)\n' "$name" "$kind" "$anchored"
      continue
    fi
    "$adit" prior-map deviations "$folder" --prior "$prior" --out "$work/dev" --truth-scene "$session/scene.ply" \
      "${aligned[@]}" --json > "$work/deviations.json" ||
      { echo "bench-deviations: $name $kind: adit prior-map deviations failed ($work/deviations.json)" >&2; exit 1; }
    read -r pp rp pr rr < <(field "$work/deviations.json" \
      '" ".join("%.3f" % j["truth"][k] for k in ("precision_points", "recall_points", "precision_regions", "recall_regions"))')
    printf '%-24s %-9s %9s %9s %9s %9s %9s\n' "$name" "$kind" "$after" "$pp" "$rp" "$pr" "$rr"
    rows+=("$kind $pp $rp $pr $rr")
  done
done
printf '%s\n' "${rows[@]}" | awk '
  { n[$1]++; for (i = 2; i <= 5; i++) { s[$1, i] += $i; if (n[$1] == 1 || $i < w[$1, i]) w[$1, i] = $i } }
  END { for (k in n) printf "%-9s mean %.3f %.3f %.3f %.3f, worst %.3f %.3f %.3f %.3f (%d drives; points p r, regions p r)\n",
          k, s[k, 2] / n[k], s[k, 3] / n[k], s[k, 4] / n[k], s[k, 5] / n[k], w[k, 2], w[k, 3], w[k, 4], w[k, 5], n[k] }'
