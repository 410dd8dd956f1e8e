#!/usr/bin/env bash
# Installs rcfd's build and test dependencies from Debian 12 packages (run as root, or with sudo).
# Every dependency of the project is named here; docker/Dockerfile installs the same list.
#   --build-only  leaves out the tools only the tests use (ParaView, Chromium, Node.js, Slurm, QEMU; the image
#                 of docker/Dockerfile builds without tests)
set -euo pipefail
test_tools=1
for arg in "$@"; do
  case "$arg" in
    --build-only) test_tools=0 ;;
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
  zlib1g-dev             # the gzip-compressed files of OpenFOAM cases (rcfd-solve import-openfoam)
  binutils               # ld -r, nm, objcopy: the AVX-512 kernel variant of a portable build (cmake/KernelVariants.cmake)
)
if [ "$test_tools" = 1 ]; then
  # The XDMF sidecars of the HDF5 outputs must open in ParaView: scripts/check-paraview.py opens them
  # with ParaView's own reader (pvpython) and reads the HDF5 files independently with h5py
  # (test ParaView.OpensEveryJobOutputThroughItsSidecar).
  packages+=(paraview python3-paraview python3-h5py python3-numpy)
  # The browser tests of the web page (tests/web): chromium, driven headless by playwright-core from
  # Node.js and npm (tests/web/package.json), which also run the OpenAPI meta-schema validator
  # (tests/openapi). The machine's own Node.js (20) with its npm is kept where there is one; Debian's
  # otherwise.
  packages+=(chromium)
  # rcfd-server --executor slurm calls sbatch, squeue and scancel of the site's Slurm; the tests start
  # a single-node cluster of their own (tests/slurm: slurmctld, slurmd, munged).
  packages+=(slurm-wlm munge)
  # The portable build on CPUs it cannot be run on here: qemu-x86_64 emulates an AVX2 CPU without
  # AVX-512 and one without AVX2 (tests/portable).
  packages+=(qemu-user)
  command -v node > /dev/null && command -v npm > /dev/null || packages+=(nodejs npm)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
