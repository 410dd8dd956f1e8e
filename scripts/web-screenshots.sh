#!/usr/bin/env bash
# Regenerates the screenshots of the web page in docs/ (docs/web-job.png, docs/web-compare.png): a real
# rcfd-server with two spray jobs (the quick slice and the slice with draft plates, each on a small
# analytic database), photographed by headless chromium. Needs a build (scripts/build.sh), chromium and
# node (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
npm ci --prefix tests/web --no-audit --no-fund >/dev/null
cmake --build build --target rcfd-server rcfd-solve rcfd-test-web >/dev/null
RCFD_WEB_SCREENSHOTS="$(pwd)/docs" build/tests/rcfd-test-web --gtest_filter='WebBrowser.DocsScreenshots'
