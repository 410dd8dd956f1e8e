#!/usr/bin/env bash
# Installs rcfd's build and test dependencies from Debian 12 packages (run as root, or with sudo).
# Every dependency of the project is named here; docker/Dockerfile installs the same list.
#   --without-paraview  leaves out ParaView, which only the ParaView check of the tests uses (the image
#                       of docker/Dockerfile builds without tests)
set -euo pipefail
# The XDMF sidecars of the HDF5 outputs must open in ParaView: scripts/check-paraview.py opens them with
# ParaView's own reader (pvpython) and reads the HDF5 files independently with h5py
# (test ParaView.OpensEveryJobOutputThroughItsSidecar).
paraview_packages=(paraview python3-paraview python3-h5py python3-numpy)
for arg in "$@"; do
  case "$arg" in
    --without-paraview) paraview_packages=() ;;
    *) echo "install-deps.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done
packages=(
  cmake ninja-build g++ pkg-config git
  libeigen3-dev          # dense/sparse linear algebra (recurrence Gram matrix, pressure solver)
  libhdf5-dev            # field databases and results
  libboost-dev           # Boost.Asio / Boost.Beast for the server and client
  nlohmann-json3-dev     # JSON
  libvalijson-dev        # JSON Schema (draft 7) validation
  libsqlite3-dev sqlite3 # job store
  libssl-dev             # OpenSSL: HMAC-SHA256 of the server's page tokens
  jq                     # composes job files in scripts/pipeline.sh (the README main command)
  libcli11-dev           # command lines
  libspdlog-dev          # logging
  libgtest-dev libgmock-dev  # tests
  libbenchmark-dev       # micro-benchmarks
)
# Node.js and npm run the OpenAPI meta-schema validator (tests/openapi); a Node.js from elsewhere that
# brings its own npm is kept.
command -v node > /dev/null && command -v npm > /dev/null || packages+=(nodejs npm)
missing=()
for p in "${packages[@]}" "${paraview_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
