#!/usr/bin/env bash
# The README's main job, with no hardware and no network: simulate a short
# survey of a mine drift with a wheeled robot and a VLP-16 (or reuse the one
# already generated), replay it through aditd with the embedded default
# configuration, and score the trajectory against the simulation's ground truth.
set -euo pipefail
cd "$(dirname "$0")/.."
session=build/sessions/demo
if [ ! -f "$session/lidar.pcap" ]; then
  build/bin/adit sim --scene mine --platform robot --sensor VLP-16 --duration 60 --seed 1 --out "$session"
else
  echo "demo: reusing the simulated session in $session"
fi

build/bin/aditd --config firmware-config/default.yaml
trajectory=$(ls -td build/state/sessions/*/ | head -n 1)trajectory.tum

echo
echo "=== accuracy against the simulation's ground truth"
build/bin/adit eval traj --ref "$session/truth_body.tum" --est "$trajectory" --align se3 --max-diff 0.02 \
  --svg "${trajectory%.tum}"
echo
echo "demo: trajectory  $trajectory"
echo "demo: plots       ${trajectory%.tum}-plan.svg, ${trajectory%.tum}-ape.svg"
echo "demo: truth       $session/truth_body.tum, scene $session/scene.ply, targets $session/targets.csv"
