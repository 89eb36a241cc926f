#!/usr/bin/env bash
# Loop detection over a set of simulated drives: for each, aditd maps the
# recording (`aditd --once`, the same runs as scripts/bench-map.sh: reused while
# their folder is there) and `adit eval loops` judges the loops its closer
# accepted against the truth; then the set's precision and recall, mean and worst.
#
# Usage: scripts/bench-loops.sh [DRIVE ...]
#   DRIVE = scene:platform:seconds:seed (adit sim's options); without arguments the
#   drives of docs/LOOPS.md "Measured": the three 300 s loops round the mine level,
#   the straight drifts, the building and the 120 s mine drive.
# ADIT_BUILD_DIR: the build tree whose bin/ runs and which holds the sessions (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
loop_drives=(mine:robot:300:5 mine:robot:300:6 mine:robot:300:7 drift:robot:150:1 drift:robot:90:2 drift:robot:90:3
             building:robot:60:1 building:robot:60:2 mine:robot:120:11)
[ $# -gt 0 ] || set -- "${loop_drives[@]}"
use_drives bench-map "$@"
printf '%-22s %9s %9s %9s %6s %10s %12s %10s %10s\n' drive keyframes revisits accepted false precision recall stretches "worst err"
results=()
for drive in "${drives[@]}"; do
  session=$(sim_session "$drive" "$runs") || exit $?
  name=$(basename "$session")
  work="$runs/$name"
  folder=$(map_once "$session" "$work" "${ADIT_BENCH_YAML:-}") || exit 1
  "$build/bin/adit" eval loops --session "$folder" --truth "$session/truth_body.tum" --json > "$work/loops.json" ||
    { echo "bench-loops: $drive: adit eval loops failed ($work/loops.json)" >&2; exit 1; }
  python3 - "$name" "$work/loops.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[2]))
pct = lambda v: "n/a" if v is None else f"{100 * v:.1f} %"
print(f"{sys.argv[1]:<22} {j['keyframes']:>9} {j['revisit_keyframes']:>9} {j['accepted']:>9} {j['false_accepted']:>6} "
      f"{pct(j['precision']):>10} {pct(j['recall']):>12} {j['recalled_stretches']:>4} of {len(j['revisit_stretches']):<3} "
      f"{j['error_m']['max']:>8.4f} m")
PY
  results+=("$work/loops.json")
done
python3 - "${results[@]}" <<'PY'
import json, sys
runs = [json.load(open(f)) for f in sys.argv[1:]]
precisions = [r["precision"] for r in runs if r["precision"] is not None]
recalls = [r["recall"] for r in runs if r["recall"] is not None]
false = sum(r["false_accepted"] for r in runs)
accepted = sum(r["accepted"] for r in runs)
print(f"{len(runs)} drives: {accepted} loops accepted, {false} false; precision mean {100 * sum(precisions) / len(precisions):.1f} %, "
      f"worst {100 * min(precisions):.1f} %; recall mean {100 * sum(recalls) / len(recalls):.1f} %, worst {100 * min(recalls):.1f} %; "
      f"loop error worst {max(r['error_m']['max'] for r in runs):.4f} m, {max(r['error_deg']['max'] for r in runs):.3f} deg")
PY
