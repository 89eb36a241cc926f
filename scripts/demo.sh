#!/usr/bin/env bash
# The README's main job, the whole story with no hardware and no network
# beyond loopback: simulate a one-minute survey of a mine drift by a wheeled
# robot with a VLP-16 (or reuse the one already generated); start aditd on it
# with the embedded default configuration; start mapping from the client as
# the tablet would; watch the live pose; stop; download the map; and score the
# run against the simulation's ground truth.
#
# The tablet's web app (`adit console`) runs beside aditd for the whole demo:
# open the address it prints in a browser to watch the live map.
#   --console   leave aditd and the console running at the end (Ctrl-C stops them)
# ADIT_DEMO_WATCH_S: seconds of live watching (default 45; the recording is 60 s).
# ADIT_CONSOLE_LISTEN: the console's address (default 0.0.0.0:8080).
set -euo pipefail
cd "$(dirname "$0")/.."
keep_console=false
for arg in "$@"; do
  case "$arg" in
    --console) keep_console=true ;;
    *) echo "demo.sh: unknown option '$arg' (only --console)" >&2; exit 2 ;;
  esac
done
listen=${ADIT_CONSOLE_LISTEN:-0.0.0.0:8080}
session=build/sessions/demo
config=firmware-config/default.yaml
client=(--payload demo --lcm-url 'udpm://239.255.76.67:7667?ttl=0' --timeout 5)
watch_s=${ADIT_DEMO_WATCH_S:-45}

if [ ! -f "$session/lidar.pcap" ]; then
  echo "=== simulating a survey session (adit sim)"
  build/bin/adit sim --scene mine --platform robot --sensor VLP-16 --duration 60 --seed 1 --out "$session"
else
  echo "=== reusing the simulated session in $session"
fi

echo
echo "=== starting aditd with $config"
mkdir -p build/state
build/bin/aditd --config "$config" > build/state/aditd.log 2>&1 &
aditd_pid=$!
trap 'kill $aditd_pid 2>/dev/null || true' EXIT
build/bin/adit ping "${client[@]}" > /dev/null

echo "=== starting adit console on $listen (log build/state/console.log)"
build/bin/adit console "${client[@]}" --listen "$listen" --data-dir build/state/console \
  --sessions-dir build/state/sessions > build/state/console.log 2>&1 &
console_pid=$!
trap 'kill $aditd_pid $console_pid 2>/dev/null || true' EXIT
port=${listen##*:}
console_up=false
for _ in $(seq 1 50); do
  if (exec 3<> "/dev/tcp/127.0.0.1/$port") 2> /dev/null; then console_up=true; break; fi
  kill -0 $console_pid 2>/dev/null || break
  sleep 0.1
done
sleep 0.3; kill -0 $console_pid 2>/dev/null || console_up=false
if $console_up; then
  host=$(hostname -I 2>/dev/null | awk '{print $1}')
  echo "demo: console  http://127.0.0.1:$port/${host:+  (on the network: http://$host:$port/)}"
else
  echo "demo: the console did not start (port $port taken? see build/state/console.log); the demo goes on without it"
fi

echo "=== adit start"
start_output=$(build/bin/adit start "${client[@]}")
echo "$start_output"
id=$(sed -n 's/.*session \([0-9TZ-]*\).*/\1/p' <<< "$start_output" | head -n 1)
folder=build/state/sessions/$id

echo
echo "=== adit watch (${watch_s} s of the live pose and health)"
build/bin/adit watch "${client[@]}" --duration "$watch_s"

echo
echo "=== adit stop"
build/bin/adit stop "${client[@]}"
for _ in $(seq 1 120); do
  build/bin/adit status "${client[@]}" | grep -q 'state     IDLE' && break
  sleep 0.5
done
build/bin/adit status "${client[@]}"

echo
echo "=== adit download"
build/bin/adit download "${client[@]}" --format ply --out "$folder/download.ply"

if ! $keep_console; then
  kill -TERM $aditd_pid $console_pid 2>/dev/null || true
  wait $aditd_pid || true
  wait $console_pid || true
  trap - EXIT
fi

echo
echo "=== accuracy of the trajectory against the simulation's ground truth"
build/bin/adit eval traj --ref "$session/truth_body.tum" --est "$folder/trajectory.tum" --align se3 --max-diff 0.02 \
  --svg "$folder/trajectory"
echo
echo "=== accuracy of the downloaded map against the true scene surfaces"
build/bin/adit eval map --map "$folder/download.ply" --scene "$session/scene.ply" \
  --ref "$session/truth_body.tum" --est "$folder/trajectory.tum" --within 0.05
echo
echo "demo: session    $folder (summary.json, map.ply, map.las, tiles/, keyframes.tum; aditd log build/state/aditd.log)"
echo "demo: map        $folder/download.ply (as the tablet downloaded it)"
echo "demo: trajectory $folder/trajectory.tum (the odometry's, as published), $folder/map_trajectory.tum (the map's poses)"
echo "demo: plots      $folder/trajectory-plan.svg, $folder/trajectory-ape.svg"
echo "demo: truth      $session/truth_body.tum, scene $session/scene.ply, targets $session/targets.csv"
if $console_up && ! $keep_console; then
  echo "demo: console    http://127.0.0.1:$port/ while the demo ran (scripts/demo.sh --console keeps it running)"
fi
if $keep_console && $console_up; then
  echo
  echo "demo: aditd and the console keep running: http://127.0.0.1:$port/ (Ctrl-C stops them)"
  wait $console_pid || true
fi
