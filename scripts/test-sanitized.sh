#!/usr/bin/env bash
# The sanitizer pass of the test suite (docs/stability.md, "Sanitizers"): builds rcfd-solve and the test
# executables of the chosen areas with AddressSanitizer + UndefinedBehaviorSanitizer (CMakePresets.json
# "asan", into build-asan/) and runs those areas' tests under the "asan" test preset (its ASAN_OPTIONS,
# 60 random whole jobs with a 300 s bound).
#   bash scripts/test-sanitized.sh [AREA ...]
# Without arguments: RCFD_SANITIZED_AREAS, else the areas CI runs (below). `all` builds everything and
# runs the whole suite (what `cmake --workflow --preset asan` does).
set -euo pipefail
cd "$(dirname "$0")/.."
# The areas CI runs: the readers of untrusted bytes (OpenFOAM files, HDF5 databases, scenes), the
# numerical stages a job runs on its inputs, and the stability suite's whole jobs through rcfd-solve.
ci_areas="core scene fields import geometry recurrence tracers spray stability"
areas=("$@")
[ ${#areas[@]} -gt 0 ] || read -r -a areas <<< "${RCFD_SANITIZED_AREAS:-$ci_areas}"
cmake --preset asan > /dev/null
if [ "${areas[*]}" = all ]; then
  cmake --build --preset asan -j "$(nproc)"
  ctest --preset asan
  exit
fi
targets=(rcfd-solve)
for a in "${areas[@]}"; do
  [ -d "tests/$a" ] || { echo "$0: no test area tests/$a" >&2; exit 2; }
  targets+=("rcfd-test-$a")
done
cmake --build --preset asan -j "$(nproc)" --target "${targets[@]}"
labels=$(IFS='|'; echo "${areas[*]}")
ctest --preset asan -L "^($labels)\$"
