#!/usr/bin/env bash
# The console's resident memory once it holds a whole session's map: aditd
# replays a simulated session (real time x SPEED, its own LCM group on
# loopback) with `adit console` following it, no browser; after the session
# stops and the console has caught up, prints the points it holds and its
# VmRSS and VmHWM.
#
# Usage: SPEED=3 scripts/bench-console-memory.sh DRIVE [ADIT_BINARY]
#   DRIVE as in scripts/bench-map.sh (e.g. mine:robot:600:1: 4.6 M map points); ADIT_BINARY: another build's adit
#   to compare (default: the build tree's).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
use_drives bench-console "$1"
session=$(sim_session "$1" "$runs") || exit $?
bin=${2:-$build/bin/adit}
w=$runs/$(basename "$session")
rm -rf "$w"
mkdir -p "$w"
url='udpm://239.255.76.99:7699?ttl=0'
aditd_config "$session" "$w" "${SPEED:-1.0}" | sed "s#url: udpm://239.255.76.67:7667?ttl=0#url: $url#" > "$w/aditd.yaml"
printf 'session:\n  products: false\n  autostart: true\n' >> "$w/aditd.yaml"
grep -q "$url" "$w/aditd.yaml" || { echo "bench-console-memory: the session's LCM URL was not replaced" >&2; exit 1; }
payload=$(awk '/^  id:/ {print $2; exit}' "$w/aditd.yaml")
"$bin" console --payload "$payload" --lcm-url "$url" --listen 127.0.0.1:8391 --data-dir "$w/console" \
  --web-dir tools/console-web > "$w/console.log" 2>&1 &
console=$!
trap 'kill $console ${aditd:-} 2>/dev/null || true' EXIT
sleep 1
"$build/bin/aditd" --config "$w/aditd.yaml" > "$w/aditd.log" 2>&1 &
aditd=$!
until grep -q "stopped;" "$w/aditd.log"; do
  kill -0 $aditd 2>/dev/null || { echo "bench-console-memory: aditd ended ($w/aditd.log)" >&2; exit 1; }
  sleep 2
done
sleep 15  # the console asks for what it lacks once the stream is quiet
points=$(curl -s http://127.0.0.1:8391/api/state | python3 -c 'import json, sys; print(json.load(sys.stdin)["map_points"])')
printf 'console holds %s points (aditd: %s): VmRSS %.1f MB, VmHWM %.1f MB\n' "$points" \
  "$(grep -o '[0-9]* map points' "$w/aditd.log" | tail -1)" \
  "$(awk '/VmRSS/ {print $2 / 1024}' /proc/$console/status)" "$(awk '/VmHWM/ {print $2 / 1024}' /proc/$console/status)"
