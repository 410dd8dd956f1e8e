# Shared by the long-run scripts (paper.sh, referee.sh): resumable jobs with their progress.
# Expects $solve, the rcfd-solve to run.

# Runs one job resumably: skipped when DIR/summary.json exists, else run (or resumed from its
# checkpoint) with every 20th progress line on the terminal and everything in DIR.log.
run_job() {
  local name=$1 job=$2 dir=$3
  if [ -f "$dir/summary.json" ]; then
    echo "== $name: done ($dir/summary.json)"
    return
  fi
  echo "== $name (log $dir.log)"
  "$solve" run "$job" --out "$dir" 2>&1 | tee -a "$dir.log" | grep --line-buffered -E '%|done|error|cancelled' |
    awk -v n="$name" '{ if (/%/) { if (NR % 20 == 1) print "   " n ": " $0 } else print "   " n ": " $0; fflush() }'
  [ -f "$dir/summary.json" ] || { echo "$0: $name did not finish; see $dir.log" >&2; exit 1; }
}

# The absolute path of an example job's scene file (resolved against the job's own directory), so that
# a job written elsewhere runs from there.
example_scene() {
  local example=$1 scene
  scene=$(jq -r '.scene_file' "$example")
  echo "$(cd "$(dirname "$example")" && cd "$(dirname "$scene")" && pwd)/$(basename "$scene")"
}

# Writes EXAMPLE with its scene file made absolute and PATCH (a JSON object) merged in to OUT.
write_job_with_absolute_scene() {
  local example=$1 patch=$2 out=$3
  [ -f "$example" ] || { echo "$0: no $example" >&2; exit 2; }
  jq --arg scene "$(example_scene "$example")" --argjson patch "$patch" '(.scene_file = $scene) * $patch' \
    "$example" > "$out"
}
