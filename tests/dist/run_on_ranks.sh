#!/usr/bin/env bash
# `swirl run` on several MPI ranks (issue 19, points 1, 5, 6 and 7): the same
# scene (SPH, self-gravity by the tree, the direct sum or the FMM, both; block time
# steps; DFSPH and boundary particles; probes,
# obstacle forces and moving obstacles; inlets and outlets) on 1 (no mpirun), 2, 3 and 4 ranks
# (x 1 and 2 threads) gives byte-identical frames (VTK, and HDF5 written through parallel HDF5), diagnostics, probes.csv and checkpoints; a run resumes on another rank count and ends with the one-rank
# bytes; a blow-up stops every rank with the one-rank
# message and keeps the frames; a scene part that is not distributed yet is
# refused once with status 2 and leaves no folder; more ranks than particles
# are refused; SIGINT to mpirun stops every rank with a checkpoint that
# resumes to the one-rank bytes.
#
#   run_on_ranks.sh MPIEXEC SWIRL EXAMPLES   (EXAMPLES: the examples/ folder)
set -uo pipefail
mpiexec=$1 swirl=$2 examples=$3
scene=$examples/dam_break.toml
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

on_ranks() {  # on_ranks N ARGS...: swirl on N ranks (1: without mpirun); status in $status
  local ranks=$1; shift
  if [ "$ranks" -eq 1 ]; then
    "$swirl" "$@" >"$out/stdout" 2>"$out/stderr"
  else
    "$mpiexec" -n "$ranks" --oversubscribe --timeout 240 "$swirl" "$@" >"$out/stdout" 2>"$out/stderr"
  fi
  status=$?
}
# same_files REF DIR WHAT: every frame (the boundary particles' too; VTK and
# HDF5, the latter written by every rank through parallel HDF5), the
# diagnostics, probes.csv (when REF has one) and every checkpoint of REF, byte
# for byte in DIR.
same_files() {
  local ref=$1 dir=$2 what=$3 f n=0
  for f in "$ref"/particles_*.vtp "$ref"/particles.pvd "$ref"/boundary_*.vtp "$ref"/boundary.pvd \
           "$ref"/particles_*.h5 "$ref"/particles.xdmf "$ref"/boundary_*.h5 "$ref"/boundary.xdmf \
           "$ref"/diagnostics.csv "$ref"/probes.csv "$ref"/checkpoints/*.swc; do
    [ -e "$f" ] || continue
    n=$((n + 1))
    cmp -s "$f" "$dir/${f#"$ref"/}" || fail "$what: ${f#"$ref"/} differs from the one-rank file"
  done
  [ "$n" -ge 4 ] || fail "$what: the one-rank run wrote only $n files to compare"
}

# against_one NAME WHAT FILES ARGS...: `swirl run ARGS` for 30 steps
# (checkpoints every 10) on 1, 2 and 3 ranks, the runs on several ranks
# compared with same_files; then on 3 ranks to step 17 (checkpoints every 5)
# resumed on 2 from step 15, and FILES (space-separated) compared with the
# one-rank run's.
against_one() {
  local name=$1 what=$2 files=$3 n f; shift 3
  on_ranks 1 run "$@" --steps 30 --checkpoint-every-steps 10 --out "$out/${name}_1"
  [ "$status" -eq 0 ] || { fail "$what on 1 rank: status $status"; cat "$out/stderr"; }
  for n in 2 3; do
    on_ranks "$n" run "$@" --steps 30 --checkpoint-every-steps 10 --out "$out/${name}_$n"
    [ "$status" -eq 0 ] || { fail "$what on $n ranks: status $status"; cat "$out/stderr"; }
    same_files "$out/${name}_1" "$out/${name}_$n" "$what on $n ranks"
  done
  local dir="$out/${name}_resume_3_2"
  on_ranks 3 run "$@" --steps 17 --checkpoint-every-steps 5 --out "$dir"
  [ "$status" -eq 0 ] || { fail "$what resume 3 -> 2: the first part: status $status"; cat "$out/stderr"; }
  on_ranks 2 run --resume "$dir" --steps 15 --checkpoint-every-steps 10
  [ "$status" -eq 0 ] || { fail "$what resume 3 -> 2: status $status"; cat "$out/stderr"; }
  for f in $files; do
    cmp -s "$out/${name}_1/$f" "$dir/$f" || fail "$what resume 3 -> 2 ranks: $f differs from the uninterrupted one-rank run"
  done
}

# About 1 900 particles (spacing 3 cm), 30 steps, a frame every 10 steps.
small=(--set particles.0.spacing=0.03 --set output.interval=0.004)

# 1. Float, fixed dt, row-major cells: 2, 3 and 4 ranks against one.
on_ranks 1 run "$scene" "${small[@]}" --steps 30 --checkpoint-every-steps 10 --out "$out/float_1"
[ "$status" -eq 0 ] || { fail "float on 1 rank: status $status"; cat "$out/stderr"; }
for n in 2 3 4; do
  on_ranks "$n" run "$scene" "${small[@]}" --steps 30 --checkpoint-every-steps 10 --out "$out/float_$n"
  [ "$status" -eq 0 ] || { fail "float on $n ranks: status $status"; cat "$out/stderr"; }
  same_files "$out/float_1" "$out/float_$n" "float on $n ranks"
  [ "$(grep -c 'swirl run: done' "$out/stdout")" -eq 1 ] || fail "float on $n ranks: the summary is not printed exactly once"
done

# 1a. Two threads on each rank (OMP_NUM_THREADS is 1 in this test's
#     environment): 2 ranks x 2 threads, the float run and the Plummer sphere
#     of section 4, against the one-rank files.
on_ranks 2 run "$scene" "${small[@]}" --steps 30 --checkpoint-every-steps 10 --threads 2 --out "$out/float_2x2"
[ "$status" -eq 0 ] || { fail "float on 2 ranks x 2 threads: status $status"; cat "$out/stderr"; }
same_files "$out/float_1" "$out/float_2x2" "float on 2 ranks x 2 threads"

# 1b. The summary's communication figures (dist::Traffic, inside the steps)
#     and the halo's ghosts per particle, as mean and max over 2 ranks.
on_ranks 2 run "$scene" "${small[@]}" --steps 3 --out "$out/traffic" --summary-json "$out/traffic.json"
[ "$status" -eq 0 ] || { fail "traffic on 2 ranks: status $status"; cat "$out/stderr"; }
for key in mpi_collectives_per_step_mean mpi_messages_per_step_max mpi_bytes_sent_per_step_mean \
           mpi_bytes_received_per_step_max halo_ghosts_per_particle_mean; do
  grep -Eq "\"$key\": *[0-9.]*[1-9]" "$out/traffic.json" || fail "traffic on 2 ranks: no positive $key in the summary"
done

# 2. Double, adaptive steps, Morton cells with a Verlet skin (the order kept
#    while no particle of any rank moved half the skin): 3 ranks against one.
dbl=("${small[@]}" --set 'simulation.precision="double"' --set 'simulation.dt="adaptive"'
     --set simulation.dt_max=4e-4 --set 'sph.grid.cell_order="morton"' --set sph.grid.skin=0.005)
on_ranks 1 run "$scene" "${dbl[@]}" --until 0.012 --checkpoint-every 0.004 --out "$out/double_1"
[ "$status" -eq 0 ] || { fail "double on 1 rank: status $status"; cat "$out/stderr"; }
on_ranks 3 run "$scene" "${dbl[@]}" --until 0.012 --checkpoint-every 0.004 --out "$out/double_3"
[ "$status" -eq 0 ] || { fail "double on 3 ranks: status $status"; cat "$out/stderr"; }
same_files "$out/double_1" "$out/double_3" "double, adaptive, skin on 3 ranks"

# 3. Resume on another rank count: 2 ranks to step 17 (checkpoints at 5, 10,
#    15), then 3 ranks from step 15 to 30; and 4 ranks resumed on 1.
for pair in "2 3" "4 1"; do
  set -- $pair
  dir="$out/resume_$1_$2"
  on_ranks "$1" run "$scene" "${small[@]}" --steps 17 --checkpoint-every-steps 5 --out "$dir"
  [ "$status" -eq 0 ] || { fail "resume $1 -> $2: the first part: status $status"; cat "$out/stderr"; }
  on_ranks "$2" run --resume "$dir" --steps 15 --checkpoint-every-steps 10
  [ "$status" -eq 0 ] || { fail "resume $1 -> $2: status $status"; cat "$out/stderr"; }
  for f in particles_000003.vtp diagnostics.csv checkpoints/checkpoint_000000000030.swc; do
    cmp -s "$out/float_1/$f" "$dir/$f" || fail "resume $1 -> $2 ranks: $f differs from the uninterrupted one-rank run"
  done
done

# 4. Self-gravity (the locally essential tree): a Plummer sphere of 1 000
#    stars, 12 steps, on 2 and 4 ranks against one; then SPH with self-gravity,
#    drag and adaptive steps (a self-gravitating drop of 1 500 particles) on 3.
grav=("$examples/plummer.toml" --set particles.0.count=1000 --set output.interval=0.0625 --steps 12
      --checkpoint-every-steps 6)
on_ranks 1 run "${grav[@]}" --out "$out/gravity_1"
[ "$status" -eq 0 ] || { fail "gravity on 1 rank: status $status"; cat "$out/stderr"; }
for n in 2 4; do
  on_ranks "$n" run "${grav[@]}" --out "$out/gravity_$n"
  [ "$status" -eq 0 ] || { fail "gravity on $n ranks: status $status"; cat "$out/stderr"; }
  same_files "$out/gravity_1" "$out/gravity_$n" "gravity on $n ranks"
done
on_ranks 3 run "${grav[@]}" --threads 2 --out "$out/gravity_3x2"
[ "$status" -eq 0 ] || { fail "gravity on 3 ranks x 2 threads: status $status"; cat "$out/stderr"; }
same_files "$out/gravity_1" "$out/gravity_3x2" "gravity on 3 ranks x 2 threads"
drop=("$examples/self_gravitating_drop.toml" --set particles.0.count=1500 --until 0.1 --set output.interval=0.025)
on_ranks 1 run "${drop[@]}" --out "$out/drop_1"
[ "$status" -eq 0 ] || { fail "drop on 1 rank: status $status"; cat "$out/stderr"; }
on_ranks 3 run "${drop[@]}" --out "$out/drop_3"
[ "$status" -eq 0 ] || { fail "drop on 3 ranks: status $status"; cat "$out/stderr"; }
same_files "$out/drop_1" "$out/drop_3" "SPH with self-gravity on 3 ranks"

# 4a. Block time steps (integrate/block_steps.hpp) on ranks: a Hernquist halo
#     of 400 stars (its cusp spreads the bins over six levels, 0-5), dt =
#     1/16, against one rank as against_one does (2 and 3 ranks, resumed 3 -> 2).
#     Every sub-step's sort, active groups' essential tree and finest bin are
#     collective. Frames in HDF5 only: every rank writes its own particles
#     (nothing is gathered for them).
against_one block "block steps" "particles_000015.h5 particles.xdmf diagnostics.csv checkpoints/checkpoint_000000000030.swc" \
  "$examples/hernquist.toml" --set particles.0.count=400 --set 'simulation.time_steps="block"' --set 'output.format="hdf5"' \
  --set simulation.dt=0.0625 --set simulation.max_bin=12 --set simulation.eta=0.2 --set output.interval=0.125

# 4a'. The direct sum on ranks (every rank gathers the whole set's positions
#      and masses): a Plummer sphere of 600 stars, 6 steps, on 3 ranks against
#      one; and with block time steps on 2.
direct=("$examples/plummer.toml" --set particles.0.count=600 --set 'nbody.method="direct"' --set output.interval=0.03125)
for variant in global block; do
  extra=()
  [ "$variant" = block ] && extra=(--set 'simulation.time_steps="block"' --set simulation.dt=0.0625
                                   --set simulation.max_bin=8 --set simulation.eta=0.1)
  on_ranks 1 run "${direct[@]}" "${extra[@]}" --steps 6 --checkpoint-every-steps 3 --out "$out/direct_${variant}_1"
  [ "$status" -eq 0 ] || { fail "direct sum ($variant) on 1 rank: status $status"; cat "$out/stderr"; }
  n=3; [ "$variant" = block ] && n=2
  on_ranks "$n" run "${direct[@]}" "${extra[@]}" --steps 6 --checkpoint-every-steps 3 --out "$out/direct_${variant}_$n"
  [ "$status" -eq 0 ] || { fail "direct sum ($variant) on $n ranks: status $status"; cat "$out/stderr"; }
  same_files "$out/direct_${variant}_1" "$out/direct_${variant}_$n" "the direct sum ($variant steps) on $n ranks"
done

# 4a''. The FMM on ranks (replicated: every rank gathers the whole set and
#       runs the one-rank FMM): a Plummer sphere of 800 stars, p = 4, with
#       block time steps, against one rank as against_one does.
against_one fmm "the FMM with block steps" "particles_000015.h5 diagnostics.csv checkpoints/checkpoint_000000000030.swc" \
  "$examples/plummer.toml" --set particles.0.count=800 --set 'nbody.method="fmm"' --set nbody.fmm_order=4 \
  --set 'simulation.time_steps="block"' --set simulation.dt=0.0625 --set simulation.max_bin=8 --set simulation.eta=0.2 \
  --set 'output.format="hdf5"' --set output.interval=0.125

# 4b. Boundary particles and DFSPH (docs/sph.md): the dam break with an
#     obstacle at a 10 cm spacing (about 800 water and 1 900 boundary
#     particles: box.walls = "particles" and an obstacle_box), DFSPH in double
#     with tolerances tight enough for 9-14 iterations per solve, adaptive
#     steps, on 2 and 3 ranks against one; then resumed 3 -> 2 ranks; and the
#     thesis's solver with walls of particles (the dam break) on 3 ranks. Both
#     with probes.csv: the example's four water-height lines and the force and
#     torque on the obstacle and the walls (DFSPH's recorded density-solve
#     reaction included); the thesis's run with a pressure point and a line.
obstacle=("$examples/dam_break_obstacle.toml" --set particles.0.spacing=0.1 --set output.interval=0.05
          --set output.probes_interval=0.02 --set 'simulation.precision="double"' --set simulation.dt_max=0.01
          --set sph.dfsph.density_tolerance=2e-5 --set sph.dfsph.divergence_tolerance=2e-5)
against_one dfsph "dfsph with boundary particles" \
  "particles_000003.vtp diagnostics.csv probes.csv checkpoints/checkpoint_000000000030.swc" "${obstacle[@]}"
# 4c. The same with DFSPH's XSPH filter, surface tension and adhesion on
#     (docs/sph.md): the ghosts' velocities, densities and surface normals
#     refreshed; 3 ranks against one, and the terms did change the run.
terms=("${obstacle[@]}" --set sph.xsph=0.1 --set sph.surface_tension=0.5 --set sph.adhesion=2)
on_ranks 1 run "${terms[@]}" --steps 30 --checkpoint-every-steps 10 --out "$out/terms_1"
[ "$status" -eq 0 ] || { fail "dfsph with xsph, surface tension, adhesion on 1 rank: status $status"; cat "$out/stderr"; }
on_ranks 3 run "${terms[@]}" --steps 30 --checkpoint-every-steps 10 --out "$out/terms_3"
[ "$status" -eq 0 ] || { fail "dfsph with xsph, surface tension, adhesion on 3 ranks: status $status"; cat "$out/stderr"; }
same_files "$out/terms_1" "$out/terms_3" "dfsph with xsph, surface tension and adhesion on 3 ranks"
cmp -s "$out/dfsph_1/particles_000003.vtp" "$out/terms_1/particles_000003.vtp" &&
  fail "dfsph: sph.xsph, sph.surface_tension and sph.adhesion changed nothing"
walls=("$scene" "${small[@]}" --set 'box.walls="particles"' --steps 30 --checkpoint-every-steps 10
       --set output.obstacle_forces=true
       --set 'probes=[{name="p", point=[0.1, 0.1, 0.05]}, {name="h", line=[[0.05, 0.1, 0.0], [0.05, 0.1, 0.4]]}]')
on_ranks 1 run "${walls[@]}" --out "$out/walls_1"
[ "$status" -eq 0 ] || { fail "walls of particles on 1 rank: status $status"; cat "$out/stderr"; }
on_ranks 3 run "${walls[@]}" --out "$out/walls_3"
[ "$status" -eq 0 ] || { fail "walls of particles on 3 ranks: status $status"; cat "$out/stderr"; }
same_files "$out/walls_1" "$out/walls_3" "the thesis's solver with walls of particles on 3 ranks"
awk -F, 'NR > 1 && $2 != 0 && $3 != 0 && $4 != 0 { ok = 1 } END { exit !ok }' "$out/walls_1/probes.csv" ||
  fail "walls of particles: probes.csv holds no pressure, height or wall force to compare"

# 4d. Moving obstacles (docs/sph.md): the sloshing tank (DFSPH, float, about
#     1 300 water and 2 400 boundary particles, the tank rolling as a flap at
#     2 Hz, 8 degrees, from t = 0), with its probes.csv (two water-height
#     lines, the tank's force and torque about its moving centre), on 2 and 3
#     ranks against one, and resumed 3 -> 2. The tank's particles cross the
#     cuts as it rolls: the density solve's recorded reactions follow them.
#     Frames in VTK (rank 0, gathered) and HDF5 (every rank, its own water and
#     tank particles in their two series).
slosh=("$examples/sloshing.toml" --set particles.1.motion.ramp=0 --set particles.1.motion.amplitude_deg=8
       --set particles.1.motion.frequency=2 --set output.interval=0.05 --set 'output.format=["vtp", "hdf5"]')
against_one moving "a moving obstacle with probes" \
  "particles_000001.vtp particles_000001.h5 boundary_000001.vtp boundary_000001.h5 boundary.xdmf diagnostics.csv probes.csv checkpoints/checkpoint_000000000030.swc" \
  "${slosh[@]}"

# 4e. Inlets and outlets (sim/inlets_outlets.hpp): the tap example (DFSPH,
#     float, adaptive steps, about 8 100 boundary particles) with its drain
#     moved under the tap, so that within 30 steps the inlet adds 168
#     particles (on the last rank, migrating from there) and the outlet takes
#     105 of them again: 2 and 3 ranks against one, resumed 3 -> 2.
tap=("$examples/tap.toml" --set 'outlets.0.min=[0.1, 0.1, 0.3]' --set 'outlets.0.max=[0.2, 0.2, 0.38]'
     --set output.interval=0.03)
against_one tap "inlets and outlets" "particles_000004.vtp diagnostics.csv checkpoints/checkpoint_000000000030.swc" "${tap[@]}"
grep -q 'outlet_particles 105' "$out/stdout" || fail "inlets and outlets: the resumed run's summary has not the 105 particles removed"

# 5. A blow-up (a step far beyond the CFL limit) on 3 ranks: status 1, the
#    one-rank message exactly, printed once; frame 0 kept.
big=("${small[@]}" --set simulation.dt=0.01)
on_ranks 1 run "$scene" "${big[@]}" --steps 20 --out "$out/blow_1"
[ "$status" -eq 1 ] || fail "blow-up on 1 rank: status $status (want 1)"
grep 'blow-up' "$out/stderr" | sed "s|$out/blow_1||g" >"$out/blow_1.txt"
on_ranks 3 run "$scene" "${big[@]}" --steps 20 --out "$out/blow_3"
[ "$status" -eq 1 ] || fail "blow-up on 3 ranks: status $status (want 1)"
grep 'blow-up' "$out/stderr" | sed "s|$out/blow_3||g" >"$out/blow_3.txt"
[ -s "$out/blow_1.txt" ] || fail "blow-up on 1 rank: no message"
cmp -s "$out/blow_1.txt" "$out/blow_3.txt" || { fail "blow-up on 3 ranks: not the one-rank message"; diff "$out/blow_1.txt" "$out/blow_3.txt"; }
cmp -s "$out/blow_1/particles_000000.vtp" "$out/blow_3/particles_000000.vtp" || fail "blow-up on 3 ranks: frame 0 lost or changed"
head -c 400 "$out/blow_3.txt"; echo

# 6. What is not distributed yet is refused once, with status 2, before any folder.
on_ranks 2 run "$scene" "${small[@]}" --set 'sph.neighbour_search="hash"' --steps 2 --out "$out/refused"
[ "$status" -eq 2 ] || fail "the hash search on 2 ranks: status $status (want 2)"
[ "$(grep -c 'sph.neighbour_search = "hash" does not run on several MPI ranks yet' "$out/stderr")" -eq 1 ] ||
  fail "the hash search on 2 ranks: the refusal is not printed exactly once"
[ ! -e "$out/refused" ] || fail "the hash search on 2 ranks: the refused run created its folder"
cat "$out/stderr"
on_ranks 2 run "$examples/plummer.toml" --set 'nbody.walk="particle"' --steps 2 --out "$out/refused"
[ "$status" -eq 2 ] || fail "the particle walk on 2 ranks: status $status (want 2)"
grep -q 'nbody.walk = "particle" does not run on several MPI ranks yet' "$out/stderr" ||
  fail "the particle walk on 2 ranks: not said why"
[ ! -e "$out/refused" ] || fail "the particle walk on 2 ranks: the refused run created its folder"

# 7. The folder's lock and files are rank 0's: a second run into a folder
#    holding another run is refused on every rank with status 2.
on_ranks 2 run "$scene" "${small[@]}" --steps 2 --out "$out/float_1"
[ "$status" -eq 2 ] || fail "a run into another run's folder on 2 ranks: status $status (want 2)"
grep -q "swirl: error" "$out/stderr" || fail "a run into another run's folder: no error message"

# 8a. Too big for the hosts' memory: refused once, before anything is
#     built, with the estimate per rank and the host that is short (all ranks
#     here share one host and its free memory).
on_ranks 2 run "$examples/random_box.toml" --set particles=2000000000 --out "$out/huge"
[ "$status" -eq 2 ] || fail "2e9 particles on 2 ranks: status $status (want 2)"
[ "$(grep -c '2000000000 particles on 2 MPI ranks need about .* GB of memory on each rank and .* GB on rank 0' "$out/stderr")" -eq 1 ] ||
  { fail "2e9 particles on 2 ranks: the estimate per rank is not said exactly once"; cat "$out/stderr"; }
grep -q "GB on host .* for its 2 ranks, more than the" "$out/stderr" || fail "2e9 particles on 2 ranks: the host is not named"
[ ! -e "$out/huge" ] || fail "2e9 particles on 2 ranks: the refused run created its folder"

# 8. More ranks than particles: said before anything runs, status 2.
on_ranks 4 run "$scene" --set particles.0.spacing=0.29 --steps 2 --out "$out/few"
[ "$status" -eq 2 ] || fail "1 particle on 4 ranks: status $status (want 2)"
grep -q "1 particles on 4 MPI ranks: every rank needs at least one particle" "$out/stderr" ||
  fail "1 particle on 4 ranks: not said"

# 9. SIGINT to mpirun (a user's Ctrl-C) stops every rank after the same step,
#    rank 0 writes a checkpoint and says so once, and no rank is left running;
#    resumed on 3 ranks to a later step, the run ends with the bytes of an
#    uninterrupted one-rank run. (mpirun's own status is not swirl's: it only
#    has to be a failure.)
dir="$out/sigint"
"$mpiexec" -n 2 --oversubscribe --timeout 240 "$swirl" run "$scene" "${small[@]}" --steps 100000 \
  --checkpoint-every-steps 1000 --out "$dir" >"$out/stdout" 2>"$out/stderr" &
launcher=$!
for _ in $(seq 600); do [ -e "$dir/particles_000003.vtp" ] && break; sleep 0.1; done
kill -INT "$launcher"
wait "$launcher"
status=$?
[ "$status" -ne 0 ] || fail "SIGINT on 2 ranks: status 0"
[ "$(grep -c 'swirl run: interrupted at t = ' "$out/stdout" "$out/stderr" | awk -F: '{s += $2} END {print s}')" -eq 1 ] ||
  { fail "SIGINT on 2 ranks: the interruption is not reported exactly once"; cat "$out/stdout" "$out/stderr"; }
sleep 1
pgrep -f -- "--out $dir" >/dev/null && fail "SIGINT on 2 ranks: a rank is still running"
checkpoint=$(ls "$dir"/checkpoints/checkpoint_*.swc 2>/dev/null | tail -1)
if [ -z "$checkpoint" ]; then
  fail "SIGINT on 2 ranks: no checkpoint written"
else
  stopped=$((10#$(basename "$checkpoint" .swc | sed 's/checkpoint_//')))
  echo "SIGINT on 2 ranks: stopped at step $stopped"
  target=$(((stopped / 10 + 2) * 10))
  on_ranks 1 run "$scene" "${small[@]}" --steps "$target" --checkpoint-every-steps 10 --out "$out/sigint_ref"
  [ "$status" -eq 0 ] || { fail "SIGINT reference: status $status"; cat "$out/stderr"; }
  on_ranks 3 run --resume "$dir" --steps $((target - stopped)) --checkpoint-every-steps 10
  [ "$status" -eq 0 ] || { fail "SIGINT resumed on 3 ranks: status $status"; cat "$out/stderr"; }
  last_frame=$(printf 'particles_%06d.vtp' $((target / 10)))
  for f in "$last_frame" diagnostics.csv "checkpoints/$(printf 'checkpoint_%012d.swc' "$target")"; do
    cmp -s "$out/sigint_ref/$f" "$dir/$f" || fail "SIGINT on 2 ranks, resumed on 3: $f differs from the uninterrupted one-rank run"
  done
fi

[ "$failures" -eq 0 ] && echo "run_on_ranks: all checks passed"
exit $((failures > 0))
