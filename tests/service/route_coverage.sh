#!/usr/bin/env bash
# route_coverage.sh - checks schemas/openapi.yaml with a real OpenAPI linter (@redocly/cli, pinned
# in tools/openapi-lint and installed by deploy/deps.sh), then checks that every operation it
# describes (method and path) was answered at least once during the service tests: tests/run.sh
# points SVC_ROUTES_LOG at one file that every poro-server started by the tests appends its
# request lines to (--access-log; logfmt, "... msg=request method=GET route=/v1/jobs status=200
# ..."). Run after the other service tests.
#   bash tests/service/route_coverage.sh BUILD_DIR ROUTES_LOG
set -u
build=${1:-build}
log=${2:-$build/service-routes.log}
cd "$(dirname "$0")/../.."
redocly=tools/openapi-lint/node_modules/.bin/redocly
export REDOCLY_TELEMETRY=off REDOCLY_SUPPRESS_UPDATE_NOTICE=true NO_COLOR=1

check() { # name, status (0 = holds), why
	if [ "$2" -eq 0 ]; then echo "PASS $1"; else echo "FAIL $1: $3"; fi
}

if [ ! -x "$redocly" ]; then
	check openapi_linter_installed 1 "$redocly missing: run deploy/deps.sh"
	exit 1
fi
out=$("$redocly" lint --format=stylish schemas/openapi.yaml 2>&1)
status=$?
check openapi_lint_clean "$status" "$(echo "$out" | tail -20)"
# problems are printed as "FILE:LINE:COL  severity  rule  message" (notices about Node.js are not)
warnings=$(echo "$out" | grep -cE 'openapi\.yaml:[0-9]+:[0-9]+ +warning')
check openapi_lint_no_warnings "$([ "$warnings" -eq 0 ]; echo $?)" "$(echo "$out" | grep -m5 -E 'warning')"

tmpdir=$(mktemp -d)
trap 'rm -rf "$tmpdir"' EXIT
bundle=$tmpdir/openapi.json
"$redocly" bundle schemas/openapi.yaml -o "$bundle" > /dev/null 2>&1
if [ ! -s "$bundle" ]; then
	check openapi_bundles_to_json 1 "redocly bundle wrote nothing"
	exit 1
fi
if [ ! -s "$log" ]; then
	check routes_log_present 1 "no requests logged in $log (run the service tests first)"
	exit 1
fi
python3 - "$bundle" "$log" <<'PY'
import json, re, sys
spec = json.load(open(sys.argv[1]))
pair = re.compile(r'([A-Za-z_]+)=("(?:[^"\\]|\\.)*"|\S*)')
seen = set()
for line in open(sys.argv[2], errors="replace"):
    f = dict(pair.findall(line))
    if f.get("msg") == "request" and "status" in f:
        seen.add((f.get("method"), f.get("route")))
methods = {"get", "put", "post", "delete", "patch", "head", "options"}
for path, item in sorted(spec["paths"].items()):
    for method in sorted(m for m in item if m in methods):
        name = "route_exercised_%s_%s" % (method.upper(), path)
        if (method.upper(), path) in seen:
            print("PASS " + name)
        else:
            print("FAIL %s: no test request answered on this route" % name)
PY
