#!/usr/bin/env bash
# Instructions per tracer-step of the motion kernel's functions, for one or more rcfd-bench binaries,
# counted by callgrind on the paper-scale tracer headline (3 steps, 1 thread). Instruction counts are
# deterministic, so they compare binaries when this VM's speed drifts too much for timings to see a
# change of a few percent; they are not time (a cache miss costs no instructions), so confirm a gain
# with bench/ab-tracers.sh. About 30 s per binary. Example:
#   bench/callgrind-tracers.sh /tmp/rcfd-bench-old build/rcfd-bench
set -euo pipefail
if [ $# -lt 1 ]; then
  echo "usage: $0 BENCH [BENCH ...]" >&2
  exit 2
fi
command -v valgrind > /dev/null || { echo "$0: valgrind is not installed (apt-get install valgrind)" >&2; exit 2; }
export OMP_WAIT_POLICY=passive RCFD_BENCH_TRACERS_HEADLINE_ONLY=1 RCFD_BENCH_STEPS=2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for bench in "$@"; do
  valgrind --tool=callgrind --callgrind-out-file="$out/cg" "$bench" tracers --threads 1 > "$out/log" 2>&1
  tracers=$(grep -o '[0-9]* tracers, ' "$out/log" | head -1 | cut -d' ' -f1)
  steps=$((RCFD_BENCH_STEPS + 1))  # the timed steps and the untimed first one
  echo "== $bench ($tracers tracers, $steps steps)"
  callgrind_annotate "$out/cg" 2> /dev/null |
    grep -E '(MotionKernel|block::)[A-Za-z:]*' | sed -e 's/(anonymous namespace):://g' |
    sed -E 's/^ *([0-9,]+) .*(rcfd::[A-Za-z0-9_:]+)\(.*/\1 \2/' | tr -d ',' |
    awk -v n="$tracers" -v s="$steps" '{ total += $1; printf "%8.1f  %s\n", $1 / (n * s), $2 }
      END { printf "%8.1f  instructions per tracer-step in all\n", total / (n * s) }'
done
