// Fetches /v1/openapi.json from a running rcfd-server and validates it against the official OpenAPI 3.1
// meta-schema. Usage: node validate.mjs SERVER_URL TOKEN
import { Validator } from "@seriousme/openapi-schema-validator";

const [server, token] = process.argv.slice(2);
const response = await fetch(`${server}/v1/openapi.json`, { headers: { Authorization: `Bearer ${token}` } });
if (!response.ok) {
  console.error(`GET ${server}/v1/openapi.json: HTTP ${response.status}`);
  process.exit(1);
}
const document = await response.json();
const validator = new Validator();
const result = await validator.validate(document);
if (!result.valid) {
  console.error(JSON.stringify(result.errors, null, 1));
  process.exit(1);
}
if (validator.version !== "3.1") {
  console.error(`the document declares OpenAPI ${document.openapi}, validated as ${validator.version}; expected 3.1`);
  process.exit(1);
}
console.log(`valid OpenAPI ${validator.version}: ${Object.keys(document.paths).length} paths`);
