#!/usr/bin/env bash
# Targets found in the map (`adit targets find`) against the simulator's
# targets.csv, on the drives scripts/bench-products.sh mapped (run it first):
# per drive, the true targets within 30 m of the driven path, how many were
# found (a found centre within 0.3 m of a true one once the map is placed in
# the world by ref(t0)·est(t0)⁻¹, as `adit eval map` does), the false ones,
# and the rms and worst centre error of those found. docs/PRODUCTS.md.
# Usage: scripts/bench-targets.sh [DRIVE ...] (default: bench-products' six)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/sim-sessions.sh
default_drives=(mine:robot:60:1 mine:robot:60:2 mine:robot:60:3 drift:robot:90:2 building:robot:60:1 building:robot:60:2)
use_drives bench-products "$@"
[ $# -gt 0 ] || drives=("${default_drives[@]}")
for drive in "${drives[@]}"; do
  session=$(sim_session "$drive" "$runs") || exit $?
  name=$(basename "$session")
  folder=$(ls -d "$runs/$name"/state/sessions/*/ 2>/dev/null | head -1)
  [ -n "$folder" ] || { echo "bench-targets: $drive: run scripts/bench-products.sh first" >&2; exit 1; }
  "$build/bin/adit" targets find "$folder" --out "$runs/$name/targets_found.csv" > /dev/null
  printf '%-22s ' "$name"
  python3 - "$runs/$name/targets_found.csv" "$session/targets.csv" "$session/truth_body.tum" "$folder/map_trajectory.tum" <<'PY'
import sys, math, bisect
def q2r(x,y,z,w):
    return [[1-2*(y*y+z*z),2*(x*y-z*w),2*(x*z+y*w)],[2*(x*y+z*w),1-2*(x*x+z*z),2*(y*z-x*w)],[2*(x*z-y*w),2*(y*z+x*w),1-2*(x*x+y*y)]]
def read_tum(f):
    out=[]
    for l in open(f):
        if l.startswith('#') or not l.strip(): continue
        v=list(map(float,l.split())); out.append(v)
    return out
def pose(v): return q2r(*v[4:8]), v[1:4]
def mul(A,B): return [[sum(A[i][k]*B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
def mv(A,x): return [sum(A[i][k]*x[k] for k in range(3)) for i in range(3)]
def T(A): return [[A[j][i] for j in range(3)] for i in range(3)]
found_f, truth_f, ref_f, est_f = sys.argv[1:5]
ref=read_tum(ref_f); est=read_tum(est_f)
t0=est[0][0]; ts=[r[0] for r in ref]; i=bisect.bisect_left(ts,t0); r=ref[min(i,len(ref)-1)]
Rr,tr=pose(r); Re,te=pose(est[0])
R=mul(Rr,T(Re)); t=[tr[k]-mv(R,te)[k] for k in range(3)]
found=[list(map(float,l.split(',')[1:5])) for l in open(found_f).readlines()[1:]]
truth=[list(map(float,l.split(',')[1:4])) for l in open(truth_f).readlines()[1:]]
path=[ [v[1],v[2],v[3]] for v in ref if v[0]>=t0 and v[0]<=est[-1][0]]
def d(a,b): return math.dist(a,b)
near=[k for k,tt in enumerate(truth) if min(d(tt,p) for p in path[::20])<=30]
fw=[[mv(R,f[:3])[k]+t[k] for k in range(3)]+[f[3]] for f in found]
matched=set(); errs=[]; false=0
for f in fw:
    j=min(range(len(truth)),key=lambda k:d(truth[k],f[:3])); e=d(truth[j],f[:3])
    if e<0.3: matched.add(j); errs.append(e)
    else: false+=1
missed=[k+1 for k in near if k not in matched]
rms=math.sqrt(sum(e*e for e in errs)/len(errs)) if errs else float('nan')
print(f"within30m {len(near)} found {len(matched & set(near))} missed {missed} false {false} rms_m {rms:.4f} max_m {max(errs) if errs else float('nan'):.4f}")
PY
done
