#!/usr/bin/env bash
# The paper's lab bed end to end (docs/paper-reproduction.md): for ProCell without and with draft
# plates, the coarse-grained CFD-DEM database job (examples/jobs/VARIANT-database.json), the D0
# calibration against its reference period (the paper's 35 s per D0, 5 s discarded), a spray over the
# reference period with one tracer per parcel (against the coverage the full simulation recorded), and
# one hour of spray at the selected D0 with the scene's 472,850 tracers; then a table of what each gives and the
# beds' coverage distributions in one figure (OUT_DIR/coverage.svg, the paper's Fig. 12). Each database also
# gets its droplet paths (OUT_DIR/db-VARIANT/droplet-paths.json: where the bed catches the spray).
#   bash scripts/paper.sh OUT_DIR [VARIANT ...]
# VARIANT: procell-coarse-grained (no plates) and procell-coarse-grained-draft-plates (default: both).
# Resumable: run it again with the same OUT_DIR; finished jobs are kept, interrupted ones resume from
# their checkpoints. A database job takes hours on 2 cores (docs/performance.md), so put OUT_DIR outside
# the repository. RCFD_PAPER_SPRAY_S sets the spray duration (default 3600 s), RCFD_PAPER_STAGES the
# stages to run (default "database calibration comparison spray"), RCFD_SOLVE the rcfd-solve to run (default
# build/rcfd-solve; a copy lets a rebuild go on beside a long job). Progress goes to the terminal and to
# each job's log in OUT_DIR. Needs a build and jq.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: $0 OUT_DIR [VARIANT ...]" >&2
  exit 2
fi
out=$(mkdir -p "$1" && cd "$1" && pwd)
shift
variants=("$@")
[ ${#variants[@]} -gt 0 ] || variants=(procell-coarse-grained procell-coarse-grained-draft-plates)
spray_s=${RCFD_PAPER_SPRAY_S:-3600}
stages=${RCFD_PAPER_STAGES:-database calibration comparison spray}
solve=${RCFD_SOLVE:-$(pwd)/build/rcfd-solve}
command -v jq > /dev/null || { echo "$0: jq is not installed (apt-get install jq)" >&2; exit 2; }
[ -x "$solve" ] || { echo "$0: no build; run scripts/build.sh" >&2; exit 2; }

source scripts/job-lib.sh
wants() { [[ " $stages " == *" $1 "* ]]; }

# A spray job on the database of variant $v: FILE, the scene's rcfd settings to change, duration, checkpoint
# interval [s].
write_spray_job() {
  jq -n --arg scene "$scene" --argjson patch "$patch" --arg db "$out/db-$v/database.h5" --argjson rcfd "$2" \
    --argjson t "$3" --argjson every "$4" \
    '{kind: "spray", scene_file: $scene, scene_patch: ($patch * {rcfd: $rcfd}), database: $db,
      duration: $t, seed: 1, checkpoint_interval: $every}' > "$1"
}

for v in "${variants[@]}"; do
  example=$(pwd)/examples/jobs/$v-database.json
  # The example's scene file resolved against examples/jobs/, so the jobs run from OUT_DIR.
  write_job_with_absolute_scene "$example" '{}' "$out/db-$v.json"
  scene=$(example_scene "$example")
  patch=$(jq '.scene_patch // {}' "$example")
  # The rCFD jobs with the recommended tracer model (docs/calibration.md, "Velocity between cell
  # centres"): Eq. (10) with the mass-weighted velocity. The database job does not read it.
  patch=$(jq -n --argjson p "$patch" '$p * {rcfd: {velocity_interpolation: "mass_weighted"}}')
  wants database && run_job "$v database" "$out/db-$v.json" "$out/db-$v"
  [ -f "$out/db-$v/summary.json" ] || continue
  # Where the full simulation's bed catches the spray (docs/paper-reproduction.md, "Where the bed
  # catches the spray"): seconds, so run whenever it is missing.
  paths=$out/db-$v/droplet-paths.json
  if [ ! -f "$paths" ]; then
    "$solve" droplet-paths "$out/db-$v/database.h5" --launches 128 --paths 64 \
      --heights 0.05,0.1,0.15,0.2,0.3,0.4 > "$paths.part" && mv "$paths.part" "$paths"
  fi

  jq -n --arg scene "$scene" --argjson patch "$patch" --arg db "$out/db-$v/database.h5" \
    '{kind: "calibration", scene_file: $scene, scene_patch: $patch, database: $db, duration: 35.0,
      discard: 5.0, seed: 1, checkpoint_interval: 5.0}' > "$out/cal-$v.json"
  wants calibration && run_job "$v calibration" "$out/cal-$v.json" "$out/cal-$v"
  [ -f "$out/cal-$v/summary.json" ] || continue

  d0=$(jq '.selected_d0' "$out/cal-$v/summary.json")
  # The spray over the full simulation's reference period with one tracer per parcel: its coverage,
  # overspray and stays against those the database job recorded on the parcels (the summary's
  # coverage_comparison and stay_comparison), the check the hour's figures rest on.
  duration=$(jq '.reference_coverage.duration_s // empty' "$out/db-$v/summary.json")
  if [ -n "$duration" ]; then
    tracers=$(jq '.reference_coverage.parcels' "$out/db-$v/summary.json")
    write_spray_job "$out/cmp-$v.json" "{\"d0\": $d0, \"tracers\": $tracers}" "$duration" 60.0
    wants comparison && run_job "$v comparison" "$out/cmp-$v.json" "$out/cmp-$v"
  fi

  write_spray_job "$out/spray-$v.json" "{\"d0\": $d0}" "$spray_s" 300.0
  wants spray && run_job "$v spray" "$out/spray-$v.json" "$out/spray-$v"
done

# One row per variant: the calibration's scores at the selected D0 and the coating after the spray.
echo
printf '%-38s %-9s %-8s %-9s %-8s %-7s %-9s %-8s %-8s %-8s %-8s %s\n' variant D0 holdup mean_stay crossing KS \
  overspray mean median p10 p90 'wall s (db/cal/spray)'
for v in "${variants[@]}"; do
  cal=$out/cal-$v/summary.json spray=$out/spray-$v/summary.json db=$out/db-$v/summary.json
  [ -f "$cal" ] || continue
  scores=$(jq -r '.selected_d0 as $d | (.d0[] | select(.value == $d)) as $r |
    def pct: if . == null then "n/a" else (. * 1000 | round / 10 | tostring) + "%" end;
    [($d | tostring), ($r.holdup_relative_error | pct), ($r.residence_time_mean_relative_error | pct),
     ($r.crossing_rate_relative_error | pct),
     (if $r.rtd_ks_distance == null then "n/a" else ($r.rtd_ks_distance * 1000 | round / 1000 | tostring) end)] | @tsv' "$cal")
  coating="n/a	n/a	n/a	n/a	n/a"
  [ -f "$spray" ] && coating=$(jq -r '[.overspray_fraction, .coverage.mean, .coverage.median, .coverage.p10, .coverage.p90] |
    map(. * 1000 | round / 1000 | tostring) | @tsv' "$spray")
  walls=$(for f in "$db" "$cal" "$spray"; do [ -f "$f" ] && jq -r '.wall_time_s | round' "$f" || echo -; done | paste -sd/)
  printf '%s\t%s\t%s\t%s\n' "$v" "$scores" "$coating" "$walls" |
    awk -F'\t' '{printf "%-38s %-9s %-8s %-9s %-8s %-7s %-9s %-8s %-8s %-8s %-8s %s\n", $1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12}'
done
echo "(holdup, mean stay, crossing rate against the database's reference period; KS of the stays; coverage after the spray)"

# The beds compared (the paper's plates-versus-no-plates findings): the spray-zone holdup and mean stay
# of the tracers over the hour against the full simulation's reference period, the overspray of the hour
# against the reference period's recorded spray, and the coverage spread.
echo
printf '%-38s %-17s %-15s %-17s %-8s %-8s %s\n' bed 'holdup rCFD/ref' 'stay s rCFD/ref' 'overspray rCFD/ref' \
  median p10 'p90 (p90-p10)'
for v in "${variants[@]}"; do
  db=$out/db-$v/summary.json spray=$out/spray-$v/summary.json
  [ -f "$db" ] && [ -f "$spray" ] || continue
  jq -r --slurpfile ref "$db" --arg v "$v" 'def r(k): . * k | round / k | tostring; $ref[0] as $d |
    [$v, (.holdup.mean | r(1)) + "/" + ($d.holdup.mean | r(1)),
     (.residence_time.mean_s | r(1000)) + "/" + ($d.residence_time.mean_s | r(1000)),
     (.overspray_fraction | r(10000)) + "/" + ($d.reference_coverage.overspray_fraction // null | if . == null then "n/a" else r(10000) end),
     (.coverage.median | r(1000)), (.coverage.p10 | r(1000)),
     (.coverage.p90 | r(1000)) + " (" + (.coverage.p90 - .coverage.p10 | r(1000)) + ")"] | @tsv' "$spray" |
    awk -F'\t' '{printf "%-38s %-17s %-15s %-17s %-8s %-8s %s\n", $1, $2, $3, $4, $5, $6, $7}'
done

# rCFD against the full simulation over the same reference period, one tracer per parcel.
echo
printf '%-38s %-9s %-10s %-10s %-10s %-8s %-10s %s\n' bed 'stay KS' 'mean stay' crossings 'coverage KS' \
  'mean' 'p90' 'overspray rCFD/ref'
for v in "${variants[@]}"; do
  cmp=$out/cmp-$v/summary.json db=$out/db-$v/summary.json
  [ -f "$cmp" ] || continue
  jq -r --slurpfile ref "$db" --arg v "$v" 'def r(k): . * k | round / k | tostring;
    def pct: if . == null then "n/a" else (. * 1000 | round / 10 | tostring) + "%" end;
    [$v, (.stay_comparison.ks_distance // null | if . == null then "n/a" else r(1000) end),
     (.stay_comparison.mean_relative_error | pct), (.stay_comparison.crossing_rate_relative_error | pct),
     (.coverage_comparison.ks_distance // null | if . == null then "n/a" else r(1000) end),
     (.coverage_comparison.mean_relative_error | pct), (.coverage_comparison.p90_relative_error | pct),
     (.overspray_fraction | r(10000)) + "/" + ($ref[0].reference_coverage.overspray_fraction | r(10000))] | @tsv' "$cmp" |
    awk -F'\t' '{printf "%-38s %-9s %-10s %-10s %-10s %-8s %-10s %s\n", $1, $2, $3, $4, $5, $6, $7, $8}'
done
echo "(the spray over the reference period with one tracer per parcel against the parcels' recorded spray)"

# Where each bed catches the spray: the droplet paths through its frames (on smoothed frames the deposit
# comes too low; docs/paper-reproduction.md, "Where the bed catches the spray").
echo
printf '%-38s %-12s %-12s %-12s %-12s %s\n' bed 'below 0.1 m' 'below 0.2 m' 'tau at 0.4 m' 'paths os' 'recorded os'
for v in "${variants[@]}"; do
  paths=$out/db-$v/droplet-paths.json db=$out/db-$v/summary.json
  [ -f "$paths" ] || continue
  jq -r --slurpfile ref "$db" --arg v "$v" 'def r(k): . * k | round / k | tostring;
    def at(y): .heights[] | select((.y_m - y) | fabs < 1e-9);
    [$v, (at(0.1).deposited_below | r(1000)), (at(0.2).deposited_below | r(1000)),
     (at(0.4).optical_depth.median | r(10)), (.overspray | r(100000)),
     ($ref[0].reference_coverage.overspray_fraction // null | if . == null then "n/a" else r(100000) end)] | @tsv' "$paths" |
    awk -F'\t' '{printf "%-38s %-12s %-12s %-12s %-12s %s\n", $1, $2, $3, $4, $5, $6}'
done

# The paper's Fig. 12: the beds' coverage distributions in one figure, once their sprays are done.
results=() labels=()
for v in "${variants[@]}"; do
  [ -f "$out/spray-$v/result.h5" ] || continue
  results+=("$out/spray-$v/result.h5")
  labels+=(--label "$v")
done
if [ ${#results[@]} -gt 0 ]; then
  "$solve" coverage-figure "${results[@]}" "${labels[@]}" --out "$out/coverage.svg" > "$out/coverage.json"
  echo "coverage distributions: $out/coverage.svg (statistics in $out/coverage.json)"
fi
