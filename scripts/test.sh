#!/usr/bin/env bash
# Installs dependencies, builds, and runs the whole test suite (what CI runs), then its sanitizer pass:
# the areas of scripts/test-sanitized.sh under ASan + UBSan (docs/stability.md, "Sanitizers";
# RCFD_TEST_SANITIZED=0 leaves it out).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
# playwright-core for the browser tests of the web page (tests/web), at the version of its lock file.
# install-deps.sh provides npm; without it the browser tests fail under CI and are skipped otherwise.
if command -v npm >/dev/null; then
  npm ci --prefix tests/web --no-audit --no-fund --loglevel=error
else
  echo "scripts/test.sh: npm not found: the browser tests of the web page (tests/web) cannot run" >&2
fi
cd build
ctest --output-on-failure -j "$(nproc)" --timeout 600
cd ..
if [ "${RCFD_TEST_SANITIZED:-1}" != 0 ]; then
  bash scripts/test-sanitized.sh
fi
