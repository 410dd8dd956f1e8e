#!/usr/bin/env bash
# What a referee asks of the paper reproduction (docs/paper-reproduction.md, "Sensitivities"): how the
# full simulation's own spray-zone statistics over its reference period (holdup, stays, crossings,
# overspray and coverage of the recorded spray, pressure drop) move with the choices rcfd makes where
# the paper is silent or differs. Each case is a database job: an example job with a patch.
#   bash scripts/referee.sh OUT_DIR [CASE ...]
# CASE (default: all but the procell ones, which take hours):
#   quick, quick-seed2        the quick spout (2 s + 2 s) and another realisation: the scatter
#   quick-cg1, quick-cg3      coarse graining 1 and 3 (dt_DEM at the same fraction of the Rayleigh time)
#   quick-stiff               Young's modulus 50 MPa instead of 5 MPa (dt_DEM 8e-6 s, the same fraction of the Rayleigh time)
#   quick-wen-yu              Wen & Yu drag instead of Beetstra's (minimum fluidisation at Wen-Yu's)
#   quick-draft-plates-e030, -e035, -e045
#                             the draft plates' lower edge at 30, 35 (the scene's) and 45 mm (10 s + 10 s)
#   procell-cg3               the 3D ProCell at coarse graining 3, 2 s + 4 s after the 3 s warm-up (about 2 h
#                             on one thread): set beside the cg 2 database's two 10 s periods
#   procell-cg3-cells10       the same on cells of 10 mm (1.85 parcel diameters, as cg 2's 7.4 mm are 2.06)
# Resumable like scripts/paper.sh: finished jobs are kept, interrupted ones resume from their
# checkpoints. RCFD_SOLVE sets the rcfd-solve to run (default build/rcfd-solve). Needs a build and jq.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: $0 OUT_DIR [CASE ...]" >&2
  exit 2
fi
out=$(mkdir -p "$1" && cd "$1" && pwd)
shift
solve=${RCFD_SOLVE:-$(pwd)/build/rcfd-solve}
command -v jq > /dev/null || { echo "$0: jq is not installed (apt-get install jq)" >&2; exit 2; }
[ -x "$solve" ] || { echo "$0: no build; run scripts/build.sh" >&2; exit 2; }
source scripts/job-lib.sh

# CASE -> "example job | job patch (merged into the job, scene_patch included)".
declare -A cases=(
  [quick]='quick-database.json|{}'
  [quick-seed2]='quick-database.json|{"seed": 2}'
  [quick-cg1]='quick-database.json|{"scene_patch": {"dem": {"coarse_graining": 1, "time_step": 1.25e-5}}}'
  [quick-cg3]='quick-database.json|{"scene_patch": {"dem": {"coarse_graining": 3}}}'
  [quick-stiff]='quick-database.json|{"scene_patch": {"particles": {"youngs_modulus": 5e7}, "dem": {"time_step": 8e-6}}}'
  [quick-wen-yu]='quick-database.json|{"scene_patch": {"gas": {"drag_model": "wen_yu"}}}'
  [quick-draft-plates-e030]='quick-draft-plates-database-10s.json|{"scene_patch": {"apparatus": {"draft_plates": {"elevation": 0.030}}}}'
  [quick-draft-plates-e035]='quick-draft-plates-database-10s.json|{}'
  [quick-draft-plates-e045]='quick-draft-plates-database-10s.json|{"scene_patch": {"apparatus": {"draft_plates": {"elevation": 0.045}}}}'
  [procell-cg3-cells10]='procell-coarse-grained-database.json|{"scene_patch": {"grid": {"cell_size": 0.01}, "dem": {"coarse_graining": 3, "time_step": 4e-5, "sample_duration": 2.0, "reference_duration": 4.0}}}'
  [procell-cg3]='procell-coarse-grained-database.json|{"scene_patch": {"dem": {"coarse_graining": 3, "time_step": 4e-5, "sample_duration": 2.0, "reference_duration": 4.0}}}'
)
order=(quick quick-seed2 quick-cg3 quick-wen-yu quick-stiff quick-cg1 quick-draft-plates-e035
       quick-draft-plates-e030 quick-draft-plates-e045)
selected=("$@")
[ ${#selected[@]} -gt 0 ] || selected=("${order[@]}")

for c in "${selected[@]}"; do
  [ -n "${cases[$c]+set}" ] || { echo "$0: no case $c (cases: ${!cases[*]})" >&2; exit 2; }
  example=$(pwd)/examples/jobs/${cases[$c]%%|*}
  write_job_with_absolute_scene "$example" "${cases[$c]#*|}" "$out/db-$c.json"
  run_job "$c database" "$out/db-$c.json" "$out/db-$c"
done

# One row per case: the reference period of its full simulation.
echo
printf '%-26s %-8s %-8s %-8s %-9s %-9s %-9s %-9s %-9s %-8s %s\n' case holdup mean_s median_s crossings \
  overspray cov_mean cov_p10 cov_p90 dp_Pa wall_s
for c in "${selected[@]}"; do
  s=$out/db-$c/summary.json
  [ -f "$s" ] || continue
  jq -r --arg c "$c" 'def r(k): . * k | round / k;
    [$c, (.holdup.mean | r(10)), (.residence_time.mean_s | r(1000)), (.residence_time.median_s | r(1000)),
     (.periods.stays.reference_period.crossings_per_member_per_s // null | if . == null then "n/a" else r(10000) end),
     (.reference_coverage.overspray_fraction // null | if . == null then "n/a" else (. * 100 | r(10000) | tostring) + "%" end),
     (.reference_coverage.mean // null | if . == null then "n/a" else r(100000) end),
     (.reference_coverage.p10 // null | if . == null then "n/a" else r(100000) end),
     (.reference_coverage.p90 // null | if . == null then "n/a" else r(100000) end),
     (.pressure_drop.mean_pa | round), (.wall_time_s | round)] | map(tostring) | @tsv' "$s" |
    awk -F'\t' '{printf "%-26s %-8s %-8s %-8s %-9s %-9s %-9s %-9s %-9s %-8s %s\n", $1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11}'
done
echo "(the full simulation's reference period: spray-zone holdup in particles, stays in s, crossings per particle per s, the recorded spray's overspray and coverage)"
