#!/usr/bin/env bash
# The regimes of the built-in CFD-DEM against their own reference (docs/calibration.md,
# "Regimes"): for each of quick (a spout), quick-draft-plates (and its plates on cell faces,
# quick-draft-plates-aligned), quick-dilute-jet and quick-coarse-cells
# (the spout on cells of 3.7 parcel diameters, several parcels per cell), the database
# job, then a calibration per tracer motion model (scripts/model-effects.jq: "mean", Eq. (9) with
# Eq. (10); "streams", the two-stream velocity; "relax", directed relaxation instead of Eq. (10);
# "langevin", relax with the Langevin velocity; each also with "-mw", the mass-weighted velocity), a
# spray job of each at its selected D0 with one tracer per parcel over the reference
# period (its coverage distribution against the full simulation's), and a table of what each selects
# and how its spray-zone stays and coverage compare.
#   bash scripts/regimes.sh OUT_DIR [REGIME ...]
# Resumable: run it again with the same OUT_DIR and finished jobs are kept, interrupted ones resume
# from their checkpoints. RCFD_REGIMES_DATABASE_JOB picks the database job variant (default
# "database"; "database-10s" samples 10 s + 10 s where examples/jobs has it), RCFD_REGIMES_MODELS the
# models (default "mean mean-mw streams relax langevin"), RCFD_REGIMES_DEM_PATCH a JSON object merged into the
# database job's scene_patch.dem (for example '{"frame_alpha_p": "coupling"}'), RCFD_SOLVE the rcfd-solve to run (default
# build/rcfd-solve; a copy lets a long run go on while the build changes). Needs a build and jq.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: $0 OUT_DIR [REGIME ...]" >&2
  exit 2
fi
out=$(mkdir -p "$1" && cd "$1" && pwd)
shift
regimes=("$@")
[ ${#regimes[@]} -gt 0 ] || regimes=(quick quick-draft-plates quick-draft-plates-aligned quick-dilute-jet quick-coarse-cells)
variant=${RCFD_REGIMES_DATABASE_JOB:-database}
read -r -a models <<< "${RCFD_REGIMES_MODELS:-mean mean-mw streams relax langevin}"
solve=${RCFD_SOLVE:-$(pwd)/build/rcfd-solve}
command -v jq > /dev/null || { echo "$0: jq is not installed (apt-get install jq)" >&2; exit 2; }

for r in "${regimes[@]}"; do
  example=$(pwd)/examples/jobs/$r-$variant.json
  [ -f "$example" ] || example=$(pwd)/examples/jobs/$r-database.json
  scene=$(pwd)/examples/$r.json
  # The example's database job, with velocity_streams among the scene's effects: the database then
  # carries the velocity spread the streams model reads (the mean model ignores it).
  jq --arg scene "$scene" --argjson effects "$(jq '.effects + ["velocity_streams"]' "$scene")" \
    --argjson dem "${RCFD_REGIMES_DEM_PATCH:-{\}}" \
    '.scene_file = $scene | .scene_patch = ((.scene_patch // {}) + {effects: $effects})
     | if $dem == {} then . else .scene_patch.dem = ((.scene_patch.dem // {}) + $dem) end' "$example" > "$out/db-$r.json"
  if [ ! -f "$out/db-$r/summary.json" ]; then
    echo "== $r: database job $(basename "$example") with the velocity spread (log $out/db-$r.log)"
    "$solve" run "$out/db-$r.json" --out "$out/db-$r" > "$out/db-$r.log" 2>&1
  fi
  for model in "${models[@]}"; do
    patch=$(jq --arg model "$model" -f scripts/model-effects.jq "$scene")
    jq -n --arg scene "$scene" --arg db "$out/db-$r/database.h5" --argjson patch "$patch" \
      '{kind: "calibration", scene_file: $scene, scene_patch: $patch, database: $db, duration: 10.0,
        discard: 2.0, seed: 1, checkpoint_interval: 5.0}' > "$out/cal-$r-$model.json"
    if [ ! -f "$out/cal-$r-$model/summary.json" ]; then
      echo "== $r: calibration, $model (log $out/cal-$r-$model.log)"
      "$solve" run "$out/cal-$r-$model.json" --out "$out/cal-$r-$model" > "$out/cal-$r-$model.log" 2>&1
    fi
    # The coverage over the reference period, one tracer per parcel (as many particles per member as the
    # reference), at the selected D0: needs a database that recorded the reference coverage.
    duration=$(jq '.reference_coverage.duration_s // empty' "$out/db-$r/summary.json")
    [ -n "$duration" ] || continue
    jq -n --arg scene "$scene" --arg db "$out/db-$r/database.h5" --argjson patch "$patch" \
      --argjson d0 "$(jq '.selected_d0' "$out/cal-$r-$model/summary.json")" \
      --argjson tracers "$(jq '.particles' "$out/db-$r/summary.json")" --argjson duration "$duration" \
      '{kind: "spray", scene_file: $scene, scene_patch: ($patch * {rcfd: {d0: $d0, tracers: $tracers}}),
        database: $db, duration: $duration, seed: 1, checkpoint_interval: 60.0}' > "$out/spray-$r-$model.json"
    if [ ! -f "$out/spray-$r-$model/summary.json" ]; then
      echo "== $r: spray over the reference period, $model (log $out/spray-$r-$model.log)"
      "$solve" run "$out/spray-$r-$model.json" --out "$out/spray-$r-$model" > "$out/spray-$r-$model.log" 2>&1
    fi
  done
done

# One row per regime and model, at the selected D0: the acceptance figures of the residence-time issue
# (coverage: KS distance and mean coverage error of the spray job against the reference coverage).
printf '%-20s %-8s %-9s %-11s %-9s %-8s %-8s %-8s %-7s %-8s %-8s %s\n' regime model D0 penalty_min RMS/floor \
  holdup mean_stay crossing KS rule cov_KS cov_mean
for r in "${regimes[@]}"; do
  for model in "${models[@]}"; do
    s=$out/cal-$r-$model/summary.json
    [ -f "$s" ] || continue
    c=$out/spray-$r-$model/summary.json
    coverage="n/a	n/a"
    [ -f "$c" ] && coverage=$(jq -r '.coverage_comparison | [(.ks_distance // "n/a" | tostring),
      (if .mean_relative_error == null then "n/a" else (.mean_relative_error * 1000 | round / 10 | tostring) + "%" end)] | @tsv' "$c")
    printf '%s\t%s\t%s\t%s\n' "$r" "$model" "$(jq -r -f scripts/calibration-scores.jq "$s")" "$coverage" |
      awk -F'\t' '{printf "%-20s %-8s %-9s %-11s %-9s %-8s %-8s %-8s %-7s %-8s %-8s %s\n", $1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12}'
  done
done
