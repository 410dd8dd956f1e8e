#!/usr/bin/env bash
# How the calibration's choice depends on the tracer count and the recurrence path: on one database,
# calibrations with each tracer count and seed (a seed is a path and a tracer placement), D0 swept up
# to where u_fluc_max binds, and one row per run: selected D0, penalty minimum, and the scores there.
#   bash scripts/calibration-convergence.sh SCENE.json DATABASE.h5 OUT_DIR [TRACERS ...]
# TRACERS defaults to "20000 one-per-particle 100000"; RCFD_SEEDS to "1 2 3"; RCFD_MODEL picks the tracer
# motion model of scripts/model-effects.jq (mean, streams: the database must carry the velocity spread,
# relax, langevin: the Langevin velocity without the spread does nothing). Resumable
# (finished calibrations are kept). Needs a build and jq.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 3 ]; then
  echo "usage: $0 SCENE.json DATABASE.h5 OUT_DIR [TRACERS ...]" >&2
  exit 2
fi
scene=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
db=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
out=$(mkdir -p "$3" && cd "$3" && pwd)
shift 3
counts=("$@")
[ ${#counts[@]} -gt 0 ] || counts=(20000 one-per-particle 100000)
seeds=${RCFD_SEEDS:-1 2 3}
solve=$(pwd)/build/rcfd-solve
command -v jq > /dev/null || { echo "$0: jq is not installed (apt-get install jq)" >&2; exit 2; }

model=${RCFD_MODEL:-mean}
effects=$(jq --arg model "$model" -f scripts/model-effects.jq "$scene")
if [ "$model" != mean ]; then
  out=$out/$model
  mkdir -p "$out"
fi
# One tracer per real particle: bed mass over the mass of one particle.
particles=$(jq '.process.bed_mass / (.particles.density * 3.141592653589793 / 6 * pow(.particles.diameter; 3)) | round' "$scene")
printf '%-9s %-5s %-10s %-11s %-9s %-8s %-8s %-8s %-7s %s\n' tracers seed selected penalty_min RMS/floor holdup mean_stay crossing KS rule
for count in "${counts[@]}"; do
  n=$count
  [ "$count" = one-per-particle ] && n=$particles
  for seed in $seeds; do
    dir=$out/t$n-s$seed
    jq -n --arg scene "$scene" --arg db "$db" --argjson n "$n" --argjson seed "$seed" --argjson effects "$effects" \
      '{kind: "calibration", scene_file: $scene, scene_patch: ({rcfd: {tracers: $n}} * $effects), database: $db,
        duration: 10.0, discard: 2.0, seed: $seed, checkpoint_interval: 5.0,
        d0_values: [0, 1e-5, 1e-4, 5e-4, 1e-3, 1e-2, 3e-2, 1e-1]}' > "$dir.json"
    [ -f "$dir/summary.json" ] || "$solve" run "$dir.json" --out "$dir" > "$dir.log" 2>&1
    printf '%s\t%s\t%s\n' "$n" "$seed" "$(jq -r -f scripts/calibration-scores.jq "$dir/summary.json")" |
      awk -F'\t' '{printf "%-9s %-5s %-10s %-11s %-9s %-8s %-8s %-8s %-7s %s\n", $1, $2, $3, $4, $5, $6, $7, $8, $9, $10}'
  done
done
