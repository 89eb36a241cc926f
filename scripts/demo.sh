#!/usr/bin/env bash
# The README's main job, the whole story with no hardware and no network
# beyond loopback: simulate a one-minute survey of a mine drift by a wheeled
# robot with a VLP-16 (or reuse the one already generated); start aditd on it
# with the embedded default configuration; start mapping from the client as
# the tablet would; watch the live pose; stop; download the map; and score the
# run against the simulation's ground truth.
#
# ADIT_DEMO_WATCH_S: seconds of live watching (default 45; the recording is 60 s).
set -euo pipefail
cd "$(dirname "$0")/.."
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

kill -TERM $aditd_pid
wait $aditd_pid || true
trap - EXIT

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
