#!/usr/bin/env bash
# Validates the OpenAPI document rcfd-server serves (/v1/openapi.json) against the official OpenAPI 3.1
# meta-schema with the npm package @seriousme/openapi-schema-validator (installed into a temporary
# directory; needs Node.js >= 18 and the npm registry). Usage: bash scripts/check-openapi.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${1:-build}")
command -v node > /dev/null && command -v npm > /dev/null || { echo "$0: needs node and npm" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
source scripts/server-lib.sh
start_rcfd_server "$bin" "$work/data" "$work/logs"
curl -sf -H "Authorization: Bearer $RCFD_TOKEN" "$RCFD_SERVER/v1/openapi.json" > "$work/openapi.json"
(cd "$work" && npm init -y > /dev/null && npm install --silent @seriousme/openapi-schema-validator@2 > /dev/null)
cat > "$work/validate.mjs" <<'JS'
import { Validator } from "@seriousme/openapi-schema-validator";
const validator = new Validator();
const result = await validator.validate(process.argv[2]);
if (!result.valid) {
  console.error(JSON.stringify(result.errors, null, 1));
  process.exit(1);
}
console.log(`valid OpenAPI ${validator.version}`);
JS
(cd "$work" && node validate.mjs "$work/openapi.json")
