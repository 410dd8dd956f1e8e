#!/usr/bin/env bash
# Installs dependencies, builds, and runs the main job on the embedded defaults: the quick pipeline
# through the job server (scripts/pipeline.sh): rcfd-server with a local data dir, database ->
# calibration -> spray on examples/quick.json submitted with the rcfd client, progress shown, the
# coverage distribution (CSV, HDF5) and its SVG downloaded into demo/. Also draws each example
# apparatus into demo/. On 2 idle cores it takes 15-25 minutes from a fresh clone (15 on an Intel Emerald
# Rapids, 25 on an AVX2 Zen 3: build ~15, pipeline ~10, mostly the CFD-DEM database job).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p demo
for scene in examples/*.json; do
  name=$(basename "$scene" .json)
  ./build/rcfd-solve validate "$scene"
  ./build/rcfd-solve geometry "$scene" --svg "demo/$name.svg" --vtk "demo/$name.vtk"
done
echo "drew demo/<example>.svg for every example scene"
bash scripts/pipeline.sh
