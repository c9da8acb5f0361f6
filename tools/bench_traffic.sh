#!/usr/bin/env bash
# Communication per step at 10^6 and 10^7 particles (issue 19, "Speed and
# scale"; docs/scaling.md): swirl run on N ranks (1 thread each, oversubscribed
# on this machine's cores), its summary's mpi_*_per_step, halo and
# essential-tree figures, the wall time and each rank's peak resident memory
# (/usr/bin/time). Writes OUT/<name>.json (the summary) and OUT/<name>.mem.
#
#   tools/bench_traffic.sh SWIRL OUT [NAME...]   (no NAME: every case below)
set -euo pipefail
swirl=$1 out=$2; shift 2
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=${OMPI_ALLOW_RUN_AS_ROOT:-1} OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}
here=$(cd "$(dirname "$0")/.." && pwd)
# The DFSPH bench's dam break (fluid block and walls of boundary particles),
# the thesis's solver: spacing 4 mm = 1.13e6 particles, 1.87 mm = 1.01e7.
sph=("$here/bench/dfsph/dam_break.toml" --set 'sph.method="wcsph"')
sph6=("${sph[@]}" --set particles.0.spacing=0.004 --set sph.smoothing_length=0.008)
sph7=("${sph[@]}" --set particles.0.spacing=0.00187 --set sph.smoothing_length=0.00374)
dfsph6=("$here/bench/dfsph/dam_break.toml" --set particles.0.spacing=0.004 --set sph.smoothing_length=0.008
        --set simulation.dt_max=0.001)
grav=("$here/examples/plummer.toml" --set output.interval=100)
run_case() {  # run_case NAME RANKS STEPS SCENE-ARGS...
  local name=$1 ranks=$2 steps=$3; shift 3
  echo "== $name: $ranks ranks, $steps steps ($(date -u +%H:%M:%S))"
  rm -rf "$out/$name.run" "$out/$name.mem"
  mpiexec -n "$ranks" --oversubscribe --bind-to none \
    /usr/bin/time -a -o "$out/$name.mem" -f "rank peak %M KB" \
    "$swirl" run "$@" --threads 1 --steps "$steps" --out "$out/$name.run" --summary-json "$out/$name.json" \
    >"$out/$name.log" 2>&1 || { echo "  failed: see $out/$name.log"; return 0; }
  rm -rf "$out/$name.run"
  python3 - "$out/$name.json" "$out/$name.mem" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
mem = [int(l.split()[2]) / 1e6 for l in open(sys.argv[2]) if l.startswith("rank peak")]
keys = [k for k in s if k.startswith(("mpi_", "halo_", "let_"))]
print(f"  particles {s['particles']}, wall {s['wall_seconds']:.1f} s, peak GB per rank {sorted(mem)}")
for k in keys: print(f"  {k} {s[k]:.6g}")
PY
}
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(sph6-2 sph6-4 dfsph6-4 grav20-2 grav20-4 sph7-4 grav7-4)
for c in "${cases[@]}"; do
  case $c in
    sph6-2) run_case "$c" 2 3 "${sph6[@]}" ;;
    sph6-4) run_case "$c" 4 3 "${sph6[@]}" ;;
    dfsph6-4) run_case "$c" 4 2 "${dfsph6[@]}" ;;
    grav20-2) run_case "$c" 2 1 "${grav[@]}" --set particles.0.count=1048576 ;;
    grav20-4) run_case "$c" 4 1 "${grav[@]}" --set particles.0.count=1048576 ;;
    sph7-4) run_case "$c" 4 2 "${sph7[@]}" ;;
    grav7-4) run_case "$c" 4 1 "${grav[@]}" --set particles.0.count=10000000 ;;
    *) echo "unknown case $c" >&2; exit 2 ;;
  esac
done
