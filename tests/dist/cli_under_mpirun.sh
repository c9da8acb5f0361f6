#!/usr/bin/env bash
# The swirl tool under mpirun (issue 19, point 1): one rank speaks, a command
# not yet distributed refuses on several ranks with status 2, and a failure on
# one rank ends every rank with status 1 and that rank's message (no hang:
# mpirun's --timeout would turn one into a failure of this test).
#
#   cli_under_mpirun.sh MPIEXEC SWIRL SCENE
set -uo pipefail
mpiexec=$1 swirl=$2 scene=$3
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

launch() {  # launch RANKS ARGS...: status in $status, output in $out/stdout, $out/stderr
  local ranks=$1; shift
  "$mpiexec" -n "$ranks" --oversubscribe --timeout 120 -x SWIRL_TEST_FAIL_ON_RANK "$swirl" "$@" \
    >"$out/stdout" 2>"$out/stderr"
  status=$?
}
count() { grep -c -- "$1" "$2" || true; }

# 1. swirl info on two ranks: printed once, naming two ranks.
export SWIRL_TEST_FAIL_ON_RANK=
launch 2 info
[ "$status" -eq 0 ] || fail "info on 2 ranks: status $status (want 0)"
[ "$(count '^swirl ' "$out/stdout")" -eq 1 ] || fail "info on 2 ranks: the banner is not printed exactly once"
grep -q "MPI .*(2 ranks)" "$out/stdout" || fail "info on 2 ranks: no 'MPI ... (2 ranks)' line"
cat "$out/stdout"

# 2. A command that is not distributed yet refuses, once, with status 2
#    (`swirl run` is: tests/dist/run_on_ranks.sh).
launch 2 hash-stats "$scene"
[ "$status" -eq 2 ] || fail "hash-stats on 2 ranks: status $status (want 2)"
[ "$(count 'does not run on several MPI ranks' "$out/stderr")" -eq 1 ] ||
  fail "hash-stats on 2 ranks: the refusal is not printed exactly once"
cat "$out/stderr"

# 3. A failure on rank 1 of 3 ends all three with status 1 and rank 1's message.
export SWIRL_TEST_FAIL_ON_RANK=1
launch 3 info
[ "$status" -eq 1 ] || fail "failure on rank 1 of 3: status $status (want 1)"
grep -q "error on rank 1 of 3.*injected failure" "$out/stderr" ||
  fail "failure on rank 1 of 3: rank 1's message is missing"
grep -q "error on rank [02]" "$out/stderr" && fail "failure on rank 1 of 3: another rank reported an error"
sed -n 1,3p "$out/stderr"

# 4. The hook on one rank names a rank that does not exist: nothing fails (status 0).
launch 1 info
[ "$status" -eq 0 ] || fail "SWIRL_TEST_FAIL_ON_RANK=1 on 1 rank: status $status (want 0: there is no rank 1)"

[ "$failures" -eq 0 ] && echo "cli_under_mpirun: all checks passed"
exit $((failures > 0))
