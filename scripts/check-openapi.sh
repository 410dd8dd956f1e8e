#!/usr/bin/env bash
# Validates the OpenAPI document rcfd-server serves (/v1/openapi.json) against the official OpenAPI 3.1
# meta-schema with the npm package @seriousme/openapi-schema-validator (tests/openapi/package-lock.json,
# installed with `npm ci` into BUILD_DIR/openapi-check). Needs Node.js >= 18 and npm; the ctest test
# openapi.ValidatesAsOpenApi31 runs it. Usage: bash scripts/check-openapi.sh [BUILD_DIR]
# Exit 0 valid, 1 invalid or failed, 77 without node or npm (ctest: skipped).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${1:-build}")
if ! command -v node > /dev/null || ! command -v npm > /dev/null; then
  echo "$0: skipped: needs node and npm (scripts/install-deps.sh installs them)" >&2
  exit 77
fi
check="$bin/openapi-check"
mkdir -p "$check"
cp tests/openapi/package.json tests/openapi/package-lock.json tests/openapi/validate.mjs "$check/"
if ! cmp -s tests/openapi/package-lock.json "$check/node_modules/.package-lock.json.rcfd" 2>/dev/null; then
  (cd "$check" && npm ci --silent --no-audit --no-fund)
  cp tests/openapi/package-lock.json "$check/node_modules/.package-lock.json.rcfd"
fi
work=$(mktemp -d)
source scripts/server-lib.sh
start_rcfd_server "$bin" "$work/data" "$work/logs"
trap 'kill "$rcfd_server_pid" 2>/dev/null || true; wait "$rcfd_server_pid" 2>/dev/null || true; rm -rf "$work"' EXIT
(cd "$check" && node validate.mjs "$RCFD_SERVER" "$RCFD_TOKEN")
