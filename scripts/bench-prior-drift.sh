#!/usr/bin/env bash
# The odometry anchored to a prior map against the same drives without it
# (issue #22's drift targets), over a set: `adit bench prior-map` on simulated
# building drives (robot and handheld, seeds 1-3) against their bim.ply, and
# on mine walks and flights (seeds 4-6) against the map aditd made of a robot
# drive of the same mine. Each run localises from the odometry's own first
# scans, then registers every scan against the prior as well. Prints each
# run, then the mean and the worst of each column.
#
# Usage: scripts/bench-prior-drift.sh [--prior-sigma-m S]   (about 6 minutes on 2 cores, sessions simulated once)
# Sessions are simulated once under build/sessions/bench-map/; runs and results go to build/bench-prior-drift/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
extra=("$@")
use_drives bench-prior-drift
field() { python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$@"; }

results=()
run() {  # NAME SESSION [PRIOR ARGS...]
  local name=$1 session=$2
  shift 2
  "$build/bin/adit" bench prior-map --session "$session" --starts 1 --json "${extra[@]}" "$@" > "$runs/$name.json"
  results+=("$runs/$name.json")
}
for platform in robot handheld; do
  for s in 1 2 3; do
    run "building-$platform-s$s" "$(sim_session "building:$platform:60:$s" "$runs")"
  done
done
for s in 4 5 6; do
  stored_sim=$(sim_session "mine:robot:90:$s" "$runs")
  stored=$(map_once "$stored_sim" "$runs/mine-robot-90-s$s")
  for kind in handheld drone; do
    run "mine-$kind-s$s" "$(sim_session "mine:$kind:60:$s" "$runs")" --prior "$stored/map.ply" \
      --prior-trajectory "$stored/trajectory.tum" --prior-truth "$stored_sim/truth_body.tum"
  done
done

python3 - "${results[@]}" <<'PY'
import json, os, sys
cols = [("anchored s", lambda w, o: w["anchored_at_s"]),
        ("drift % with", lambda w, o: w["drift_percent"]), ("drift % without", lambda w, o: o["drift_percent"]),
        ("APE rms with", lambda w, o: w["ape_rms_m"]), ("APE max with", lambda w, o: w["ape_max_m"]),
        ("APE rms without", lambda w, o: o["ape_rms_m"]), ("fitted rms with", lambda w, o: w["ape_fitted_rms_m"] if w["ape_fitted_rms_m"] is not None else float("nan")),
        ("fitted rms without", lambda w, o: o["ape_fitted_rms_m"] if o["ape_fitted_rms_m"] is not None else float("nan")),
        ("p99 ms with", lambda w, o: w["odometry_p99_ms"]), ("p99 ms without", lambda w, o: o["odometry_p99_ms"])]
print("%-20s" % "run" + "".join("%17s" % c for c, _ in cols))
groups = {}
for path in sys.argv[1:]:
    j = json.load(open(path))
    w, o = j["with_prior"], j["without_prior"]
    name = os.path.basename(path)[:-5]
    if not w["anchored"]:
        print("%-20s never localised (%d tries: %s)" % (name, w["localisation_tries"], w["failure"]))
        continue
    row = [f(w, o) for _, f in cols]
    groups.setdefault(name.split("-")[0], []).append(row)
    print("%-20s" % name + "".join("%17.4f" % v for v in row))
for g, rows in groups.items():
    n = len(rows)
    def known(i): return [r[i] for r in rows if r[i] == r[i]]  # NaN: no fit (a path along one line)
    print("%-20s" % (g + " mean") + "".join("%17.4f" % (sum(known(i)) / len(known(i)) if known(i) else float("nan")) for i in range(len(cols))))
    print("%-20s" % (g + " worst") + "".join("%17.4f" % (max(known(i)) if known(i) else float("nan")) for i in range(len(cols))))
PY
