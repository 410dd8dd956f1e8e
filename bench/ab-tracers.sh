#!/usr/bin/env bash
# A/B comparison of two rcfd-bench binaries on the tracer headline: alternating runs (this VM's
# speed drifts by up to 20% within an hour, so only interleaved runs compare), minimum and median of
# the CPU nanoseconds per tracer-step. Extra arguments are environment settings for both, e.g.
#   bench/ab-tracers.sh 5 /tmp/rcfd-bench-old build/rcfd-bench RCFD_BENCH_EFFECTS=transport,walls
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 RUNS BENCH_A BENCH_B [VAR=value ...]" >&2
  exit 2
fi
runs=$1 a=$2 b=$3
shift 3
export OMP_WAIT_POLICY=passive RCFD_BENCH_TRACERS_HEADLINE_ONLY=1
cpuNs() { env "$@" tracers --threads 1 2>&1 | grep -o '[0-9.]* CPU-ns' | cut -d' ' -f1; }
ra="" rb=""
for _ in $(seq "$runs"); do
  ra="$ra $(cpuNs "$@" "$a")"
  rb="$rb $(cpuNs "$@" "$b")"
done
summary() { tr ' ' '\n' | grep . | sort -n | awk '{v[NR]=$1} END {printf "min %.1f median %.1f CPU ns per tracer-step (%d runs)\n", v[1], v[int((NR+1)/2)], NR}'; }
echo "A $a: $(echo "$ra" | summary)"
echo "B $b: $(echo "$rb" | summary)"
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
