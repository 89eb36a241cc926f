#!/usr/bin/env bash
# Georeferencing on loop drives (docs/GEOREF.md): for each
# drive the simulator places 20 targets; aditd maps it (`aditd --once`, loop
# closure on, its default); `adit targets find` finds them in the map; four of
# the found ones (spread along the route) get control points: the simulator's
# true target positions through a made-up site transform (E ~ 500 000,
# N ~ 7 000 000, turned 123.4°), ids CP<n> so matching is by geometry;
# `adit georef` fits the map on them; every other found target is a check:
# its site position from the fit against the truth through the same
# transform. Then the same with one control point shifted 10 cm: is it flagged?
# Found targets are paired with true ones (within 0.3 m once the map is placed
# by ref(t0)·est(t0)⁻¹, as scripts/bench-targets.sh) only to choose controls
# and to score; georef itself sees no truth.
# Usage: scripts/bench-georef.sh [DRIVE ...]  (default: the three 300 s mine loops of docs/LOOPS.md)
# ADIT_GEOREF_ARGS: extra options for `adit georef`, e.g. --level.
# ADIT_BENCH_YAML: YAML appended to aditd's configuration (e.g. $'map:\n  loops_move_map: true');
# runs then go to build/bench-georef-<hash of it>.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
extra=${ADIT_BENCH_YAML:-}
suffix=""
[ -z "$extra" ] || suffix="-$(printf '%s' "$extra" | md5sum | cut -c1-8)"
use_drives "bench-georef$suffix" "$@"
[ $# -gt 0 ] || drives=(mine:robot:300:5 mine:robot:300:6 mine:robot:300:7)
printf '%-22s %6s %6s %9s %9s %9s %9s %9s %s\n' drive found checks rms_m worst_m ctrl_rms horiz_rms vert_rms shifted-10cm
for drive in "${drives[@]}"; do
  IFS=: read -r scene platform seconds seed <<< "$drive"
  name="$scene-$platform-$seconds-s$seed"
  session="$build/sessions/bench-georef/$name"
  if [ ! -f "$session/lidar.pcap" ]; then
    "$build/bin/adit" sim --scene "$scene" --platform "$platform" --sensor VLP-16 --duration "$seconds" --seed "$seed" \
      --targets 20 --out "$session" > "$runs/$name-sim.log" 2>&1 || { echo "$drive: adit sim failed" >&2; exit 1; }
  fi
  work="$runs/$name"
  folder=$(map_once "$session" "$work" "$extra") || exit 1
  "$build/bin/adit" targets find "$folder" --out "$work/found.csv" > /dev/null
  python3 - "$work" "$work/found.csv" "$session/targets.csv" "$session/truth_body.tum" "$folder/map_trajectory.tum" <<'PY'
import sys, math, bisect
work, found_f, truth_f, ref_f, est_f = sys.argv[1:6]
def q2r(x,y,z,w):
    return [[1-2*(y*y+z*z),2*(x*y-z*w),2*(x*z+y*w)],[2*(x*y+z*w),1-2*(x*x+z*z),2*(y*z-x*w)],[2*(x*z-y*w),2*(y*z+x*w),1-2*(x*x+y*y)]]
def read_tum(f): return [list(map(float,l.split())) for l in open(f) if l.strip() and not l.startswith('#')]
def mul(A,B): return [[sum(A[i][k]*B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
def mv(A,x): return [sum(A[i][k]*x[k] for k in range(3)) for i in range(3)]
def T(A): return [[A[j][i] for j in range(3)] for i in range(3)]
ref=read_tum(ref_f); est=read_tum(est_f)
t0=est[0][0]; ts=[r[0] for r in ref]; r=ref[min(bisect.bisect_left(ts,t0),len(ref)-1)]
Rr,tr=q2r(*r[4:8]),r[1:4]; Re,te=q2r(*est[0][4:8]),est[0][1:4]
R=mul(Rr,T(Re)); t=[tr[k]-mv(R,te)[k] for k in range(3)]
found=[(l.split(',')[0],list(map(float,l.split(',')[1:4]))) for l in open(found_f).readlines()[1:]]
truth=[(l.split(',')[0],list(map(float,l.split(',')[1:4]))) for l in open(truth_f).readlines()[1:]]
pairs=[]  # (truth index, found id)
for fid,f in found:
    w=[mv(R,f)[k]+t[k] for k in range(3)]
    j=min(range(len(truth)),key=lambda k:math.dist(truth[k][1],w))
    if math.dist(truth[j][1],w)<0.3 and all(p[0]!=j for p in pairs): pairs.append((j,fid))
pairs.sort()
# the made-up site: world -> site, turned 123.4 deg about up, far from the origin
a=math.radians(123.4); S=[[math.cos(a),-math.sin(a),0],[math.sin(a),math.cos(a),0],[0,0,1]]; off=[512345.678,7012345.432,1234.5]
site=lambda p:[mv(S,p)[k]+off[k] for k in range(3)]
n=len(pairs)
if n<5:
    print(f"{work.split('/')[-1]:22s} {n:6d}  too few targets found to score"); sys.exit(0)
ctrl=sorted({0,n//3,(2*n)//3,n-1})
def write_control(path, shift_index=None):
    with open(path,'w') as f:
        f.write("id,E,N,H\n")
        for c in ctrl:
            j=pairs[c][0]; p=site(truth[j][1])
            if c==shift_index: p=[p[0]+0.06,p[1]+0.08,p[2]]
            f.write(f"CP{truth[j][0]},{p[0]:.4f},{p[1]:.4f},{p[2]:.4f}\n")
write_control(work+"/control.csv"); write_control(work+"/control_shifted.csv", ctrl[1])
open(work+"/pairs.txt","w").write("\n".join(f"{truth[j][0]} {fid}" for j,fid in pairs)+"\n")
open(work+"/checks.txt","w").write("\n".join(f"{fid} "+" ".join(f"{v:.4f}" for v in site(truth[j][1])) for c,(j,fid) in enumerate(pairs) if c not in ctrl)+"\n")
open(work+"/shifted_id.txt","w").write(f"CP{truth[pairs[ctrl[1]][0]][0]}\n")
PY
  [ -f "$work/control.csv" ] || continue
  # shellcheck disable=SC2086
  "$build/bin/adit" georef "$folder" --control "$work/control.csv" --targets "$work/found.csv" --out "$work/georef" ${ADIT_GEOREF_ARGS:-} \
    > "$work/georef.txt" 2>&1 || { echo "$drive: adit georef failed ($work/georef.txt)" >&2; cat "$work/georef.txt" >&2; continue; }
  # shellcheck disable=SC2086
  "$build/bin/adit" georef "$folder" --control "$work/control_shifted.csv" --targets "$work/found.csv" ${ADIT_GEOREF_ARGS:-} \
    --out "$work/georef-shifted" > "$work/georef-shifted.txt" 2>&1 || true
  python3 - "$work" "$name" <<'PY'
import sys, math, json
work, name = sys.argv[1:3]
fitted={l.split(',')[0]:list(map(float,l.split(',')[1:4])) for l in open(work+"/georef/targets.csv").readlines()[1:]}
errs=[]; horiz=[]; vert=[]
for l in open(work+"/checks.txt"):
    if not l.strip(): continue
    fid,*p=l.split(); p=list(map(float,p)); errs.append(math.dist(fitted[fid],p))
    horiz.append(math.hypot(fitted[fid][0]-p[0],fitted[fid][1]-p[1])); vert.append(abs(fitted[fid][2]-p[2]))
r=lambda a: math.sqrt(sum(x*x for x in a)/len(a)) if a else float('nan')
g=json.load(open(work+"/georef/georef.json"))
shifted=open(work+"/shifted_id.txt").read().strip()
try:
    s=json.load(open(work+"/georef-shifted/georef.json"))
    flagged=[p["id"] for p in s["points"] if p["flagged"]]
    verdict="flagged only it" if flagged==[shifted] else f"flagged {flagged} (shifted {shifted})"
except Exception as e:
    verdict=f"georef failed: {open(work+'/georef-shifted.txt').read().strip().splitlines()[-1]}"
rms=math.sqrt(sum(e*e for e in errs)/len(errs)) if errs else float('nan')
print(f"{name:22s} {len(fitted):6d} {len(errs):6d} {rms:9.4f} {max(errs) if errs else float('nan'):9.4f} {g['rms_m']:9.4f} "
      f"{r(horiz):9.4f} {r(vert):9.4f} {verdict}")
open(work+"/score.txt","w").write(f"{rms} {max(errs) if errs else float('nan')} {len(errs)}\n")
PY
done
