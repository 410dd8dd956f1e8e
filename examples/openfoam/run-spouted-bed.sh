#!/usr/bin/env bash
# A small pseudo-2D MPPICFoam spouted bed through rcfd's server (docs/import.md, "Example: an MPPICFoam
# spouted bed through the server"): spouted-bed-case.py writes the case in rcfd's coordinates (a 0.1 m x
# 0.3 m box one 5 mm cell deep, a 10 mm jet at 30 m/s in the middle of the bottom, 5403 particles of 1.8 mm
# as a packed layer), Debian's MPPICFoam runs it on one process, then a real rcfd-server on loopback
# (started with --import-root WORK) takes, through the rcfd client, an import job of the case (the
# written times after the spin-up), a calibration job on the imported database (a few D0 values against
# the import's /reference/ holdup and stays) and a spray job at the selected D0. Their summary.json files
# go to WORK, and a table of the figures is printed (and kept in WORK/table.txt).
#
# Needs: the Debian packages openfoam (MPPICFoam, blockMesh), jq and python3 with python3-h5py and
# python3-numpy (the spout check reads the imported frames), and built rcfd binaries: RCFD_SOLVE (default
# build/rcfd-solve), RCFD_SERVER_BIN (default build/rcfd-server; not RCFD_SERVER, which is the client's
# server URL) and RCFD_CLIENT (default build/rcfd). PYTHON (default /usr/bin/python3, Debian's, which
# has h5py) runs the Python parts.
# WORK (default /tmp/rcfd-openfoam-spouted-bed) holds case/ (the OpenFOAM case, about 400 MB binary),
# server/ (the server's data directory, with its token), the job files, import-summary.json,
# calibration-summary.json, spray-summary.json, coverage.csv, database.h5 (the imported frames) and
# figures/ (their alpha_P snapshots and time average).
# Settings: JET_VELOCITY [m/s] (default 30), END_TIME [s] (1.4), SPIN_UP [s] (0.4: the written times
# before it are not imported), WRITE_INTERVAL [s] (0.005), D0_VALUES (JSON array, default
# [0, 1e-4, 1e-3, 1e-2, 3e-2, 6e-2]; the calibration extends the sweep by itself when its optimum is the
# largest), CAL_DURATION [s] per D0 (20), CAL_DISCARD [s] (1), SPRAY_S [s] (60). OMP_NUM_THREADS (default
# 1) is the threads of each job's solver: on a machine whose cores are busy with other work, two threads
# per tracer run are many times slower than one (their barriers wait for a descheduled thread).
# A finished OpenFOAM run in WORK/case with the same JET_VELOCITY, END_TIME and WRITE_INTERVAL is kept
# (REUSE_CASE=0 runs it again).
# Takes about 7.5 minutes for MPPICFoam and half a minute for the server's jobs on 2 shared cores.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
solve="$(realpath "${RCFD_SOLVE:-$root/build/rcfd-solve}")"
server_bin="$(realpath "${RCFD_SERVER_BIN:-$root/build/rcfd-server}")"
client="$(realpath "${RCFD_CLIENT:-$root/build/rcfd}")"
py="${PYTHON:-/usr/bin/python3}"
work="${WORK:-/tmp/rcfd-openfoam-spouted-bed}"
jet="${JET_VELOCITY:-30}"
end="${END_TIME:-1.4}"
spin="${SPIN_UP:-0.4}"
interval="${WRITE_INTERVAL:-0.005}"
d0_values="${D0_VALUES:-[0, 1e-4, 1e-3, 1e-2, 3e-2, 6e-2]}"
cal_s="${CAL_DURATION:-20}"
cal_discard="${CAL_DISCARD:-1}"
spray_s="${SPRAY_S:-60}"
scene="$here/spouted-bed-scene.json"
# Debian's OpenFOAM finds its etc/ files through these.
export WM_PROJECT_DIR=/usr/share/openfoam FOAM_ETC=/usr/share/openfoam/etc
mkdir -p "$work"
work="$(cd "$work" && pwd)"
cd "$work"

# --- 1. the OpenFOAM run ---------------------------------------------------------------------------
t0=$(date +%s)
settings="jet $jet end $end interval $interval"
if [ "${REUSE_CASE:-1}" = 1 ] && [ "$(cat case/settings 2>/dev/null)" = "$settings" ] &&
   grep -q '^End' case/log.MPPICFoam 2>/dev/null; then
  echo "OpenFOAM: keeping the run in $work/case (REUSE_CASE=0 runs it again)"
  foam_s=$(cat case/wall-time-s)
else
  "$py" "$here/spouted-bed-case.py" case --jet-velocity "$jet" --end-time "$end" --write-interval "$interval"
  (cd case && blockMesh > log.blockMesh && nice -n 5 MPPICFoam > log.MPPICFoam)
  foam_s=$(( $(date +%s) - t0 ))
  echo "$foam_s" > case/wall-time-s
  echo "$settings" > case/settings
  echo "OpenFOAM: MPPICFoam ran $end s in $foam_s s of wall time ($work/case/log.MPPICFoam)"
fi

# --- 2. the server ---------------------------------------------------------------------------------
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"  # the solvers inherit the server's environment
"$server_bin" --data-dir "$work/server" --listen 127.0.0.1:0 --workers 1 --solver "$solve" \
  --import-root "$work" > server.out 2> server.log &
server_pid=$!
trap 'kill "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true' EXIT
for _ in $(seq 1 200); do
  grep -q '^listening on ' server.out 2>/dev/null && break
  kill -0 "$server_pid" 2>/dev/null || { cat server.log >&2; exit 1; }
  sleep 0.05
done
url=$(sed -n 's/^listening on //p' server.out | head -n1)
[ -n "$url" ] || { echo "rcfd-server did not start listening; log: $work/server.log" >&2; exit 1; }
export RCFD_TOKEN=${RCFD_TOKEN:-$(cat server/token)}
rcfd() { "$client" --server "$url" "$@"; }
echo "server: $url (data in $work/server, log $work/server.log)"

# --- 3. import ---------------------------------------------------------------------------------------
jq -n --slurpfile s "$scene" --arg times "$spin:$end" \
  '{kind: "import", scene: $s[0], case_dir: "case", times: $times}' > import-job.json
t0=$(date +%s)
imp=$(rcfd submit import-job.json)
echo "import job $imp: case/ (times $spin:$end) onto the scene's grid"
rcfd wait "$imp"
import_s=$(( $(date +%s) - t0 ))
rcfd result "$imp" > import-summary.json
rcfd download "$imp" database.h5 -o database.h5
"$solve" database-figures database.h5 --out figures > /dev/null

# One tracer per particle, and the bed mass the imported frames hold (parcels that left through the
# outlet during the spin-up are not in them).
read -r bed_mass tracers < <(jq -r --slurpfile s "$scene" \
  '($s[0].particles) as $p | .particle_volume.first_frame_m3 as $v
   | "\($v * $p.density) \($v / (3.141592653589793 / 6 * pow($p.diameter; 3)) + 0.5 | floor)"' import-summary.json)
patch=$(jq -n --argjson m "$bed_mass" --argjson n "$tracers" '{process: {bed_mass: $m}, rcfd: {tracers: $n}}')

# --- 4. calibration ------------------------------------------------------------------------------------
jq -n --slurpfile s "$scene" --arg db "$imp" --argjson p "$patch" --argjson d0 "$d0_values" \
  --argjson t "$cal_s" --argjson discard "$cal_discard" \
  '{kind: "calibration", scene: $s[0], scene_patch: $p, database: $db, seed: 1, duration: $t,
    discard: $discard, d0_values: $d0}' > calibration-job.json
t0=$(date +%s)
cal=$(rcfd submit calibration-job.json)
echo "calibration job $cal: D0 in $d0_values, $cal_s s each, against the import's reference"
rcfd wait "$cal"
cal_wall=$(( $(date +%s) - t0 ))
rcfd result "$cal" > calibration-summary.json
d0=$(jq '.selected_d0' calibration-summary.json)
echo "calibration selected D0 = $d0 m2/s"

# --- 5. spray ------------------------------------------------------------------------------------------
jq -n --slurpfile s "$scene" --arg db "$imp" --argjson p "$patch" --argjson d0 "$d0" --argjson t "$spray_s" \
  '{kind: "spray", scene: $s[0], scene_patch: ($p | .rcfd.d0 = $d0), database: $db, seed: 1, duration: $t}' \
  > spray-job.json
t0=$(date +%s)
spray=$(rcfd submit spray-job.json)
echo "spray job $spray: $spray_s s of coating at D0 = $d0"
rcfd wait "$spray"
spray_wall=$(( $(date +%s) - t0 ))
rcfd result "$spray" > spray-summary.json
rcfd coverage "$spray" --format csv -o coverage.csv

# --- 6. the figures ------------------------------------------------------------------------------------
"$py" - "$foam_s" "$import_s" "$cal_wall" "$spray_wall" <<'PY' | tee table.txt
import json, sys
import h5py, numpy as np

foam_s, import_s, cal_s, spray_s = sys.argv[1:5]
imp = json.load(open("import-summary.json"))
cal = json.load(open("calibration-summary.json"))
spr = json.load(open("spray-summary.json"))
ref = imp["reference"]
rt = ref.get("residence_time") or {}
row = next(r for r in cal["d0"] if r["value"] == cal["selected_d0"])
sc = row.get("stay_comparison") or {}

def f(v, fmt="%.3g"):
    return "n/a" if v is None else fmt % v

# The spout: the frames' alpha_P in the two jet cells (|x| < 5 mm) and in the annulus beside them.
with h5py.File("database.h5", "r") as h:
    a = h["/frames/alpha_p"][:, 0]                      # [frame][y][x]
    nx = a.shape[2]
    jet = a[:, 2:8, nx // 2 - 1: nx // 2 + 1].mean(axis=(1, 2))           # 10 mm < y < 40 mm
    ann = np.concatenate([a[:, 2:8, 2:6], a[:, 2:8, nx - 6: nx - 2]], axis=2).mean(axis=(1, 2))
    fountain = a[:, 18:30, nx // 2 - 1: nx // 2 + 1].mean()               # 90 mm < y < 150 mm

vol_err = imp["particle_volume"]["max_relative_error"]
lines = [
    ("frames", "%d (%.4g-%.4g s, dt_rec %.4g s), parcels %d-%d"
     % (imp["frames"], imp["first_time_s"], imp["last_time_s"], imp["dt_rec"], imp["parcels"]["min"], imp["parcels"]["max"])),
    ("particle volume error (max rel.)", "%.2g %s" % (vol_err, "(ok: <= 1e-6)" if vol_err <= 1e-6 else "(FAILS: > 1e-6)")),
    ("spout: alpha_P jet / annulus", "%.3f / %.3f (10-40 mm; jet below 0.3 in %.0f %% of frames), fountain %.3f"
     % (jet.mean(), ann.mean(), 100 * (jet < 0.3).mean(), fountain)),
    ("bed pressure drop (from p)", "mean %s Pa, std %s Pa, dominant frequency %s Hz"
     % (f((ref.get("pressure_drop") or {}).get("mean_pa"), "%.1f"), f((ref.get("pressure_drop") or {}).get("std_pa"), "%.1f"),
        f((ref.get("pressure_drop") or {}).get("dominant_frequency_hz"), "%.2f"))),
    ("reference holdup", "%s particles (%s parcels)" % (f(ref["holdup"]["mean"], "%.1f"), f(ref["holdup"].get("mean_parcels"), "%.1f"))),
    ("reference stays", "%s completed, %s censored, mean %s s, %s parcels seen"
     % (rt.get("stays"), rt.get("censored"), f(rt.get("mean_s"), "%.4f"), rt.get("members"))),
    ("selected D0", "%s m2/s (rule satisfied: %s; penalty minimum %s)"
     % (cal["selected_d0"], cal["selection"]["rule_satisfied"], cal["penalty_minimum_d0"])),
    ("calibration holdup error", f(row.get("holdup_relative_error"), "%+.3f")),
    ("calibration mean stay error", f(row.get("residence_time_mean_relative_error"), "%+.3f")),
    ("calibration crossing rate error", f(row.get("crossing_rate_relative_error"), "%+.3f")),
    ("calibration KS distance", f(row.get("rtd_ks_distance"), "%.3f")),
    ("calibration stays tracers / ref.", "%s / %s (window-weighted, docs/calibration.md)"
     % (f((sc.get("tracers") or {}).get("stays"), "%.0f"), f((sc.get("reference") or {}).get("stays"), "%.0f"))),
    ("spray coverage mean", "%.4g (median %.4g, p10 %.4g, p90 %.4g) after %g s"
     % (spr["coverage"]["mean"], spr["coverage"]["median"], spr["coverage"]["p10"], spr["coverage"]["p90"], spr["sim_time_s"])),
    ("spray overspray", "%.4g" % spr["overspray_fraction"]),
    ("wall time [s]", "MPPICFoam %s, import %s (job %.1f), calibration %s (job %.1f), spray %s (job %.1f)"
     % (foam_s, import_s, imp["wall_time_s"], cal_s, cal["wall_time_s"], spray_s, spr["wall_time_s"])),
]
for k, v in lines:
    print("%-34s %s" % (k, v))
if vol_err > 1e-6:
    sys.exit("particle volume error above 1e-6")
PY
echo "summaries, coverage.csv, database.h5 and figures/ in $work"
