#!/usr/bin/env bash
# Fuzz smoke run (issue 5, "Hostile input"): builds the libFuzzer targets of
# tests/fuzz/ with clang (cmake/fuzz.cmake) and runs each for FUZZ_SECONDS on a
# copy of its seed corpus plus its kept regressions, so the repository never
# grows. Fails on any crash, sanitizer report, timeout (> 10 s for one input)
# or out-of-memory (> 2 GB), and prints how to reproduce it.
#
#   .ci/fuzz.sh                      every target, 60 s each
#   FUZZ_SECONDS=600 .ci/fuzz.sh     longer
#   .ci/fuzz.sh scene_fuzz           one target
#
# Environment: FUZZ_SECONDS (60), FUZZ_BUILD (build-fuzz), FUZZ_OUT (out/fuzz),
# FUZZ_JOBS (targets run side by side; default: all of them), FUZZ_ARGS (extra
# libFuzzer flags, e.g. -jobs or -use_value_profile=1).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

FUZZ_SECONDS=${FUZZ_SECONDS:-60}
FUZZ_BUILD=${FUZZ_BUILD:-build-fuzz}
FUZZ_OUT=${FUZZ_OUT:-out/fuzz}
FUZZ_ARGS=${FUZZ_ARGS:-}
case $FUZZ_OUT in /*) ;; *) FUZZ_OUT=$root/$FUZZ_OUT ;; esac

# Debian 12 packages: clang and its libFuzzer runtime, clang's OpenMP, the
# scene module's libraries. Installed only when missing, as `make deps` does.
packages="cmake ninja-build clang libclang-rt-14-dev libomp-dev libtomlplusplus-dev libfmt-dev"
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  echo "fuzz: installing Debian packages:$missing"
  $sudo apt-get update -q
  # shellcheck disable=SC2086
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends $missing
fi

echo "== fuzz: build ($FUZZ_BUILD)"
cmake -S tests/fuzz -B "$FUZZ_BUILD" -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build "$FUZZ_BUILD" -j "$(nproc)"

if [ $# -gt 0 ]; then
  targets="$*"
else
  targets=$(for f in tests/fuzz/*_fuzz.cpp; do basename "$f" .cpp; done)
fi
targets=$(echo "$targets" | tr '\n' ' ' | sed 's/ *$//')
# All targets at once by default: each gets its FUZZ_SECONDS of wall time and the
# whole stage stays near FUZZ_SECONDS plus the build, whatever the core count.
ntargets=$(echo "$targets" | wc -w)
jobs=${FUZZ_JOBS:-$ntargets}
[ "$jobs" -le "$ntargets" ] || jobs=$ntargets
[ "$jobs" -ge 1 ] || jobs=1

# The solvers' OpenMP is not what is fuzzed; keep one thread and no spinning.
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

run_target() {
  local t=$1 name=${1%_fuzz}
  local work="$FUZZ_OUT/$name"
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts"
  # A copy: new inputs the fuzzer finds go to out/, never into tests/.
  for d in "tests/fuzz/corpus/$name" "tests/fuzz/regressions/$name"; do
    if [ -d "$d" ]; then find "$d" -maxdepth 1 -type f ! -name '.*' ! -name '*.md' -exec cp {} "$work/corpus/" \; ; fi
  done
  local dict=()
  [ -f "tests/fuzz/$name.dict" ] && dict=("-dict=tests/fuzz/$name.dict")
  local status=0
  # shellcheck disable=SC2086
  "$FUZZ_BUILD/$t" "${dict[@]}" -max_total_time="$FUZZ_SECONDS" -rss_limit_mb=2048 -malloc_limit_mb=2048 \
    -timeout=10 -print_final_stats=1 -artifact_prefix="$work/artifacts/" $FUZZ_ARGS \
    "$work/corpus" >"$work/log.txt" 2>&1 || status=$?
  echo "$status" >"$work/status"
}

echo "== fuzz: $targets, ${FUZZ_SECONDS}s each, $jobs at a time (logs in $FUZZ_OUT/)"
failed=""
running=0
for t in $targets; do
  if [ ! -x "$FUZZ_BUILD/$t" ]; then
    echo "fuzz: no target $FUZZ_BUILD/$t" >&2
    exit 2
  fi
  rm -f "$FUZZ_OUT/${t%_fuzz}/status"
  run_target "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait

for t in $targets; do
  name=${t%_fuzz}
  work="$FUZZ_OUT/$name"
  status=$(cat "$work/status" 2>/dev/null || echo "no status")
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/log.txt" | grep -o '[0-9]*$' || true)
  cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$work/log.txt" | tail -1 || true)
  artifacts=$(find "$work/artifacts" -type f 2>/dev/null | sort)
  if [ "$status" = 0 ] && [ -z "$artifacts" ]; then
    echo "fuzz: $t ok: ${runs:-?} inputs, $cov"
    continue
  fi
  failed="$failed $t"
  echo "fuzz: $t FAILED (exit $status) after ${runs:-?} inputs; the end of $work/log.txt:" >&2
  grep -v '^#[0-9]' "$work/log.txt" | tail -n 40 >&2
  for a in $artifacts; do
    echo "fuzz: reproducer: $a" >&2
    echo "      replay:   $FUZZ_BUILD/$t $a" >&2
    echo "      minimise: $FUZZ_BUILD/$t -minimize_crash=1 -runs=100000 -exact_artifact_path=$a.min $a" >&2
    echo "      then keep it as tests/fuzz/regressions/$name/<name> (replayed by tests/*/fuzz_regressions_test.cpp)" >&2
  done
done

if [ -n "$failed" ]; then
  echo "fuzz: FAILED:$failed" >&2
  exit 1
fi
echo "fuzz: all targets passed"
