#!/usr/bin/env bash
# The price of `rcfd.integrator` on a real database: after `bash scripts/demo.sh` (or scripts/pipeline.sh),
# re-runs the quick pipeline's calibration with Euler and sprays 600 s with each integrator and two
# seeds through the job server, then prints the calibration's per-D0 metrics and the coverage
# statistics, and KS distances between the coverage histograms (integrator against seed noise).
#   bench/compare-integrators.sh [DEMO_DIR]     (default: demo; about 12 minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(cd "${1:-demo}" && pwd)
bin=$(pwd)/build
work=$(mktemp -d)
db=$(jq -r '.database' "$out/spray-job.json")
source scripts/server-lib.sh
start_rcfd_server "$bin" "$out/data" "$work"
rcfd() { "$bin/rcfd" "$@"; }
finish() { rcfd wait "$1" >/dev/null && rcfd result "$1" >"$2"; }

for integrator in midpoint euler; do
  jq --arg i "$integrator" '.scene.rcfd.integrator = $i' "$out/calibration-job.json" >"$work/cal-$integrator.json"
  finish "$(rcfd submit "$work/cal-$integrator.json")" "$work/cal-$integrator-summary.json"
  d0=$(jq '.selected_d0' "$work/cal-$integrator-summary.json")
  for seed in 1 2; do
    jq --arg i "$integrator" --argjson s "$seed" --argjson d0 "$d0" \
      '.scene.rcfd.integrator = $i | .scene.rcfd.d0 = $d0 | .seed = $s | .duration = 600' \
      "$out/spray-job.json" >"$work/spray-$integrator-$seed.json"
    finish "$(rcfd submit "$work/spray-$integrator-$seed.json")" "$work/spray-$integrator-$seed-summary.json"
  done
done

python3 - "$work" <<'PY'
import json, sys
work = sys.argv[1]
for integrator in ("midpoint", "euler"):
    d = json.load(open(f"{work}/cal-{integrator}-summary.json"))
    print(f"{integrator}: calibration selected D0 = {d['selected_d0']} ({d['wall_time_s']:.0f} s)")
    for e in d["d0"]:
        print(f"  D0 {e['value']:<7g} penalty {e['penalty']:.5f} field RMS {e['field_rms_difference']:.4f} "
              f"RTD KS {e['rtd_ks_distance']:.4f} mean residence {e['residence_time_mean_s']:.4f} s")
counts = {}
for integrator in ("midpoint", "euler"):
    for seed in (1, 2):
        d = json.load(open(f"{work}/spray-{integrator}-{seed}-summary.json"))
        c = d["coverage"]
        counts[(integrator, seed)] = c["histogram"]["counts"]
        print(f"{integrator} seed {seed}: coverage mean {c['mean']:.4f} p10 {c['p10']:.4f} p90 {c['p90']:.4f}, "
              f"overspray {d['overspray_fraction']:.4f}, {d['wall_time_s']:.0f} s")
def ks(a, b):
    ca = cb = worst = 0.0
    for x, y in zip(a, b):
        ca += x / sum(a); cb += y / sum(b); worst = max(worst, abs(ca - cb))
    return worst
keys = list(counts)
for i, a in enumerate(keys):
    for b in keys[i + 1:]:
        print(f"KS of the coverage histograms, {a} against {b}: {ks(counts[a], counts[b]):.4f}")
PY
echo "job files and summaries in $work"
