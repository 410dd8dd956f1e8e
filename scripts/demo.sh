#!/usr/bin/env bash
# Installs dependencies, builds, and runs the main job on the embedded defaults:
# validates the example scenes and draws the apparatus of each into demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p demo
for scene in examples/*.json; do
  name=$(basename "$scene" .json)
  ./build/rcfd-solve validate "$scene"
  ./build/rcfd-solve geometry "$scene" --svg "demo/$name.svg" --vtk "demo/$name.vtk"
  echo "drew demo/$name.svg"
done
