#!/usr/bin/env bash
# Debian's MPPICFoam column tutorial through rcfd's import (docs/import.md, "Example"): the case turned
# into rcfd's coordinates (column-case.py), run reconstructed in ASCII and decomposed on two processors
# in compressed binary, both imported with column-scene.json, compared, and a short spray job run on
# the import. Needs the Debian packages openfoam and openfoam-examples (and mpirun for the decomposed
# run) and a built rcfd-solve (RCFD_SOLVE, default build/rcfd-solve). WORK (default /tmp/rcfd-openfoam-column)
# holds the cases and results. END_TIME [s] (default 0.4) and WRITE_INTERVAL [s] (default 0.01) set the runs.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
solve="${RCFD_SOLVE:-$root/build/rcfd-solve}"
work="${WORK:-/tmp/rcfd-openfoam-column}"
end="${END_TIME:-0.4}"
interval="${WRITE_INTERVAL:-0.01}"
# Debian's OpenFOAM finds its etc/ files through these.
export WM_PROJECT_DIR=/usr/share/openfoam FOAM_ETC=/usr/share/openfoam/etc
mkdir -p "$work"
cd "$work"

python3 "$here/column-case.py" ascii --end-time "$end" --write-interval "$interval" --format ascii
(cd ascii && blockMesh > log.blockMesh && MPPICFoam > log.MPPICFoam)

python3 "$here/column-case.py" binary --end-time "$end" --write-interval "$interval" --format binary --compress
cat > binary/system/decomposeParDict <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }
numberOfSubdomains 2;
method simple;
coeffs { n (1 2 1); }
DICT
(cd binary && blockMesh > log.blockMesh && decomposePar > log.decomposePar &&
 mpirun --allow-run-as-root --oversubscribe -np 2 MPPICFoam -parallel > log.MPPICFoam)

"$solve" import-openfoam ascii --scene "$here/column-scene.json" --out ascii.h5 --json | tail -1 > ascii.json
"$solve" import-openfoam binary --scene "$here/column-scene.json" --out binary.h5 --json | tail -1 > binary.json
python3 - <<'PY'
import json
for name in ("ascii", "binary"):
    s = json.load(open(name + ".json"))
    r = s["reference"]
    print("%-6s decomposed=%s frames=%d dt_rec=%.4g parcels=%s volume error=%.2g holdup mean=%.1f stays=%s"
          % (name, s["decomposed"], s["frames"], s["dt_rec"], s["parcels"], s["particle_volume"]["max_relative_error"],
             r["holdup"]["mean"], (r.get("residence_time") or {}).get("stays")))
PY

cat > spray.json <<JOB
{"kind": "spray", "scene_file": "$here/column-scene.json", "database": "$work/ascii.h5", "duration": 0.2,
 "scene_patch": {"rcfd": {"tracers": 2000, "dt": 0.005},
                 "effects": ["transport", "tracer_volume_fraction", "fluctuation", "walls", "residence_time"]}}
JOB
"$solve" run spray.json --out spray > /dev/null
echo "spray job on the import: $work/spray/summary.json"
