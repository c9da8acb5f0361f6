#!/usr/bin/env bash
# check_simd_objects.sh <build-dir> [--library-only]
#
# The wide copies of the *_simd.cpp kernels (CMake's swirl_simd_sources: object
# libraries CMakeFiles/<lib>_<stem>_avx2.dir and _avx512.dir, compiled with
# -march=haswell / skylake-avx512) must define no external symbol outside their
# own namespace (isa_avx2:: / isa_avx512::) that another object also defines:
# such a symbol is an inline function (or template) the linker keeps ONE copy
# of for the whole program, and if it keeps the wide one, baseline code calls
# AVX2/AVX-512 instructions on a CPU without them (see core/simd_dispatch.hpp).
#
# For every object of a wide copy, this lists its external defined symbols
# (nm -g --defined-only) outside its namespace that are also defined by an
# object built for another instruction set: by default any other object of the
# build (libraries, apps, tests: the linker merges program-wide); with
# --library-only only the same library's baseline objects and its other
# copies. DW.ref.__gxx_personality_v0 (a data pointer to the C++ personality
# routine, the same in every object) is not code and is ignored.
# Exit status: 0 if none, 1 if any (listed), 2 on usage errors.
set -euo pipefail

usage() { echo "usage: $0 <build-dir> [--library-only]" >&2; exit 2; }
[[ $# -ge 1 && $# -le 2 ]] || usage
build=$1
scope=all
if [[ $# -eq 2 ]]; then
  [[ $2 == --library-only ]] || usage
  scope=library
fi
[[ -d $build ]] || { echo "$0: $build: not a directory" >&2; exit 2; }
command -v nm >/dev/null || { echo "$0: nm not found (binutils)" >&2; exit 2; }


# External defined symbols of an object, one mangled name a line.
# (An object may define none: awk, not grep, so that an empty list is no error.)
symbols() { nm -g --defined-only --format=posix "$1" | awk '$1 != "DW.ref.__gxx_personality_v0" {print $1}' | sort -u; }

mapfile -t wide_dirs < <(find "$build" -type d \( -name '*_avx2.dir' -o -name '*_avx512.dir' \) -path '*CMakeFiles*' | sort)
if [[ ${#wide_dirs[@]} -eq 0 ]]; then
  echo "$0: no wide SIMD objects (CMakeFiles/*_avx2.dir, *_avx512.dir) under $build: nothing to check" >&2
  exit 0
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Every object's symbols, with its object (default scope).
if [[ $scope == all ]]; then
  find "$build" -name '*.o' -path '*CMakeFiles*' | sort > "$tmp/objects"
  while read -r o; do symbols "$o" | sed "s|\$| $o|"; done < "$tmp/objects" > "$tmp/all_symbols"
fi

status=0
checked=0
for dir in "${wide_dirs[@]}"; do
  name=$(basename "$dir" .dir)
  isa=${name##*_}
  ns="isa_${isa}"
  mapfile -t objects < <(find "$dir" -name '*.o' | sort)
  for object in "${objects[@]}"; do
    checked=$((checked + 1))
    stem=$(basename "$object" .o)
    stem=${stem%.*}  # foo.cpp.o -> foo
    library=${name%_"${stem}"_"${isa}"}
    # The reference: objects that another instruction set's code may run.
    if [[ $scope == all ]]; then
      grep -v "_${isa}\.dir/" "$tmp/all_symbols" > "$tmp/reference" || true
    else
      : > "$tmp/reference"
      for other in "$(dirname "$dir")/${library}.dir" "$(dirname "$dir")/${library}"_*.dir; do
        [[ -d $other && $other != "$dir" ]] || continue
        other_isa=$(basename "$other" .dir); other_isa=${other_isa##*_}
        [[ $other_isa == "$isa" ]] && continue
        while read -r o; do symbols "$o" | sed "s|\$| $o|"; done < <(find "$other" -name '*.o') >> "$tmp/reference"
      done
    fi
    symbols "$object" > "$tmp/mine"
    # Outside the copy's namespace (mangled: <len>isa_<name>), and defined elsewhere too.
    while read -r sym; do
      demangled=$(echo "$sym" | c++filt)
      [[ $demangled == *"::${ns}::"* || $demangled == "${ns}::"* ]] && continue
      other=$(awk -v s="$sym" '$1 == s {print $2; exit}' "$tmp/reference")
      [[ -n $other ]] || continue
      echo "$object: $demangled"
      echo "    also defined by $other"
      status=1
    done < "$tmp/mine"
  done
done

if [[ $status -eq 0 ]]; then
  echo "check_simd_objects: $checked wide SIMD object(s) under $build define nothing shared outside isa_avx2::/isa_avx512:: (scope: $scope)"
else
  echo "check_simd_objects: FAILED: the symbols above may be taken from a wide copy by the linker; keep them out of *_simd.cpp (or in its namespace)" >&2
fi
exit $status
