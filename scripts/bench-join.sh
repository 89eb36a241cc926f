#!/usr/bin/env bash
# Joining sessions over a set of simulated pairs: for each seed, a robot drive
# of the mine (the stored session), then a handheld walk and a drone flight of
# the same mine (the scene is made from the seed), each mapped by aditd
# (`aditd --once`); `adit join` places each into the drive's map, searching
# with the session moved by a rigid shift first (simulated sessions start at
# the same place; the join must not rely on it), and its error is measured
# against both truths. Then each is joined to the next seed's drive (another
# mine): that must be refused. Prints each pair, the mean and the worst.
#
# Usage: scripts/bench-join.sh [SEED ...]   (default: 4 5 6; about 3 minutes a seed on 2 cores)
# Sessions are simulated once under build/sessions/bench-map/; aditd's runs and the results go to build/bench-join/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(4 5 6)
use_drives bench-join
declare -A folder sim
for s in "${seeds[@]}"; do
  for drive in "mine:robot:90:$s" "mine:handheld:60:$s" "mine:drone:60:$s"; do
    session=$(sim_session "$drive" "$runs") || exit $?
    sim[$drive]=$session
    folder[$drive]=$(map_once "$session" "$runs/$(basename "$session")") || exit 1
  done
done

field() { python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$@"; }

printf '%-22s %-7s %-8s %9s %10s %8s\n' pair joined places error-m error-deg seconds
n=0 joined=0 false_joins=0 refused=0 others=0
errors=()
for s in "${seeds[@]}"; do
  stored="mine:robot:90:$s"
  for kind in handheld drone; do
    walk="mine:$kind:60:$s"
    n=$((n + 1))
    # A shift that differs by seed: 40-60 m away, turned 100-250 degrees.
    shift=($((30 + 10 * s)) $((-20 - 5 * s)) 0.7 $((40 + 50 * s)))
    rm -f "${folder[$walk]}/joined.json"
    start=$(date +%s.%N)
    "$build/bin/adit" join "${folder[$walk]}" --to "${folder[$stored]}" --json --shift "${shift[@]}" \
      --truth "${sim[$stored]}/truth_body.tum" "${sim[$walk]}/truth_body.tum" > "$runs/join-$kind-s$s.json" || true
    secs=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {printf "%.1f", b - a}')
    result=$runs/join-$kind-s$s.json
    ok=$(field "$result" 'int(j["success"])')
    t=$(field "$result" 'j["error"]["translation_m"]')
    r=$(field "$result" 'j["error"]["rotation_deg"]')
    printf '%-22s %-7s %-8s %9.3f %10.3f %8s\n' "$kind s$s -> robot s$s" "$([ "$ok" = 1 ] && echo yes || echo no)" \
      "$(field "$result" 'str(j["places_agreeing"]) + "/" + str(j["places_tried"])')" "$t" "$r" "$secs"
    [ "$ok" != 1 ] || { joined=$((joined + 1)); errors+=("$t $r"); }
  done
done
# Another mine: each walk and flight against the next seed's drive (nothing is written when refused).
for i in "${!seeds[@]}"; do
  [ ${#seeds[@]} -gt 1 ] || break
  s=${seeds[$i]} o=${seeds[$(((i + 1) % ${#seeds[@]}))]}
  for kind in handheld drone; do
    others=$((others + 1))
    result=$runs/join-$kind-s$s-to-s$o.json
    cp "${folder[mine:$kind:60:$s]}/joined.json" "$runs/keep.json" 2>/dev/null || rm -f "$runs/keep.json"
    if "$build/bin/adit" join "${folder[mine:$kind:60:$s]}" --to "${folder[mine:robot:90:$o]}" --json > "$result"; then
      false_joins=$((false_joins + 1))
      printf '%-22s %-7s another mine: a FALSE join\n' "$kind s$s -> robot s$o" yes
    else
      refused=$((refused + 1))
      printf '%-22s %-7s another mine: %s\n' "$kind s$s -> robot s$o" no "$(field "$result" 'j["failure"]')"
    fi
    [ ! -f "$runs/keep.json" ] || mv "$runs/keep.json" "${folder[mine:$kind:60:$s]}/joined.json"
  done
done
printf '%s\n' "${errors[@]}" | awk -v n="$n" -v j="$joined" -v f="$false_joins" -v o="$others" '
  NF == 2 {st += $1; sr += $2; if ($1 > wt) wt = $1; if ($2 > wr) wr = $2}
  END {printf "joined %d of %d; error mean %.3f m %.3f deg, worst %.3f m %.3f deg; other mines: %d false joins of %d\n",
       j, n, (j ? st / j : 0), (j ? sr / j : 0), wt, wr, f, o}'
