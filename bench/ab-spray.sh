#!/usr/bin/env bash
# A/B comparison of two rcfd-bench binaries on the issue-5 headline, `rcfd-bench spray --json` on 2
# threads with libgomp's default wait policy (as the server and rcfd-solve run): alternating runs
# (this VM's speed drifts by 10-30% within minutes, so only interleaved runs compare), each run's
# projected wall time for 1 h of process and stage times, then the ratio B/A of each pair and its median.
# Each run takes a few seconds. Extra arguments are environment settings for both, e.g.
#   bench/ab-spray.sh 6 /tmp/rcfd-bench-old build/rcfd-bench RCFD_BENCH_INTEGRATOR=euler
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 RUNS BENCH_A BENCH_B [VAR=value ...]" >&2
  exit 2
fi
runs=$1 a=$2 b=$3
shift 3
command -v jq > /dev/null || { echo "$0: jq is not installed (apt-get install jq)" >&2; exit 2; }
hours() {  # prints: hours motion tvf deposition spray sort
  env "$@" spray --threads "${THREADS:-2}" --json 2> /dev/null | tail -1 |
    jq -r '[.projected_wall_seconds_for_1h / 3600, .stage_ms_per_step.motion,
            .stage_ms_per_step.tracer_volume_fraction, .stage_ms_per_step.deposition,
            .stage_ms_per_step.spray, .stage_ms_per_step.sort] | map(. * 1000 | round / 1000) | @tsv'
}
ratios=""
printf '%-4s %-9s %-8s %-6s %-6s %-6s %-6s %s\n' run 1h[h] motion tvf dep spray sort binary
for k in $(seq "$runs"); do
  ra=$(hours "$@" "$a")
  rb=$(hours "$@" "$b")
  printf '%-4s %s\t%s\n' "$k" "$ra" "$a" "$k" "$rb" "$b"
  ratios="$ratios $(awk -v x="${ra%%$'\t'*}" -v y="${rb%%$'\t'*}" 'BEGIN { printf "%.3f", y / x }')"
done
echo "B/A per pair:$ratios"
echo "$ratios" | tr ' ' '\n' | grep . | sort -n |
  awk '{v[NR]=$1} END {printf "median B/A %.3f (%d pairs; < 1: B is faster)\n", v[int((NR+1)/2)], NR}'
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
