#!/usr/bin/env bash
# The quick pipeline through the job server, as a process engineer runs it:
#   start rcfd-server on its embedded defaults (SQLite and artifacts in a local data dir),
#   submit database -> calibration -> spray for examples/quick.json with the rcfd client,
#   watch their progress, then download the coverage distribution (CSV, HDF5) and its SVG.
# Needs a build (scripts/build.sh) and jq. Output in demo/ (RCFD_DEMO_DIR overrides).
# RCFD_DEMO_SPRAY_S sets the simulated spray time (default 600 s; 3600 s is the paper's hour).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${RCFD_DEMO_DIR:-demo}
spray_s=${RCFD_DEMO_SPRAY_S:-600}
mkdir -p "$out/data"
out=$(cd "$out" && pwd)
bin=$(pwd)/build

source scripts/server-lib.sh
start_rcfd_server "$bin" "$out/data" "$out"
rcfd() { "$bin/rcfd" "$@"; }
echo "server: $RCFD_SERVER (data in $out/data, log $out/server.log)"

scene="$(pwd)/examples/quick.json"
jq -n --slurpfile s "$scene" '{kind: "database", scene: $s[0], seed: 1}' >"$out/database-job.json"
db=$(rcfd submit "$out/database-job.json")
echo "database job $db: CFD-DEM of the quick slice sampled into database.h5"

jq -n --slurpfile s "$scene" --arg db "$db" \
  '{kind: "calibration", scene: $s[0], database: $db, seed: 1, duration: 10.0, discard: 2.0,
    d0_values: [0, 1e-5, 1e-4, 5e-4, 1e-3, 1e-2]}' >"$out/calibration-job.json"
cal=$(rcfd submit "$out/calibration-job.json")
echo "calibration job $cal: D0 sweep against the full simulation"

rcfd wait "$db"
rcfd wait "$cal"
d0=$(rcfd result "$cal" | jq '.selected_d0')
echo "calibration selected D0 = $d0 m2/s"

# One tracer per particle for the coverage distribution (docs/accuracy.md: the scene's 20,000 tracers
# serve the calibration's spray-zone statistics; the coverage's tail needs every particle).
jq -n --slurpfile s "$scene" --arg db "$db" --argjson d0 "$d0" --argjson t "$spray_s" \
  '($s[0].particles) as $p | ($s[0].process.bed_mass / ($p.density * 3.141592653589793 / 6 * pow($p.diameter; 3)) + 0.5 | floor) as $n
   | {kind: "spray", scene: ($s[0] | .rcfd.d0 = $d0 | .rcfd.tracers = $n), database: $db, seed: 1, duration: $t,
      checkpoint_interval: 60.0}' >"$out/spray-job.json"
spray=$(rcfd submit "$out/spray-job.json")
echo "spray job $spray: $spray_s s of coating"
rcfd wait "$spray"

rcfd coverage "$spray" --format csv -o "$out/coverage.csv"
rcfd coverage "$spray" --format h5 -o "$out/coverage.h5"
rcfd download "$spray" coverage.svg -o "$out/coverage.svg"
rcfd result "$spray" >"$out/spray-summary.json"
rcfd result "$cal" >"$out/calibration-summary.json"
rcfd result "$db" >"$out/database-summary.json"
jq -r '"coverage: mean \(.coverage.mean), median \(.coverage.median), p10 \(.coverage.p10), p90 \(.coverage.p90); overspray \(.overspray_fraction)"' \
  "$out/spray-summary.json"
echo "wrote $out/coverage.csv, $out/coverage.h5, $out/coverage.svg and the three summaries"
