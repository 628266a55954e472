#!/usr/bin/env bash
# dashboard_test.sh - the dashboard in a real browser (docs/web.md, "Tests"): a real poro-server
# on 127.0.0.1 (port chosen at run time, tests/service/lib.sh), real poro-worker and poro-solve,
# real SQLite, and Debian's chromium (/usr/bin/chromium) driven by playwright-core (pinned in
# tests/web/package-lock.json, installed by deploy/deps.sh; no browser is downloaded). What
# dashboard.mjs checks is listed at its top; its screenshots are kept in BUILD/web-screenshots/.
#   bash tests/web/dashboard_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
shots="$build/web-screenshots"
rm -rf "$shots" && mkdir -p "$shots"

if [ ! -f tests/web/node_modules/playwright-core/package.json ] || [ ! -x /usr/bin/chromium ]; then
	check web_test_tools_installed 1 "playwright-core or /usr/bin/chromium missing: run deploy/deps.sh"
	exit 1
fi
if [ ! -f web/vendor/uplot/uPlot.esm.js ]; then
	check web_vendor_installed 1 "web/vendor/uplot missing: run deploy/deps.sh"
	exit 1
fi
# the server finds web/ beside its build directory (BUILD/../web), as it does after make
svc_start main || { check web_server_starts 1 "poro-server did not start"; exit 1; }
alice=$(svc_token main alice user)
bob=$(svc_token main bob user)
root=$(svc_token main root admin)
pool=$(svc_token main pool worker)
(umask 077
 printf '%s\n' "$pool" > "$SVC_TMP/pool.token"
 python3 -c 'import json, sys; json.dump(dict(zip(["alice", "bob", "root"], sys.argv[1:])), open(sys.argv[4], "w"))' \
	"$alice" "$bob" "$root" "$SVC_TMP/tokens.json")

# bob's job, which alice must not see: submitted and cancelled, so no worker runs it
python3 - tests/cases/terzaghi.json "$SVC_TMP/bob.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.001
json.dump({"case": c, "name": "bob-private"}, open(sys.argv[2], "w"))
PY
code=$(svc_req POST /v1/jobs "$bob" -d @"$SVC_TMP/bob.json")
bob_job=$(json '["id"]' < "$SVC_BODY")
svc_req POST "/v1/jobs/$bob_job/cancel" "$bob" > /dev/null
check web_setup_other_users_job "$([ "$code" = 201 ]; echo $?)" "POST /v1/jobs answered $code"

WEB_URL=$SVC_URL WEB_TOKENS="$SVC_TMP/tokens.json" WEB_WORKER_TOKEN_FILE="$SVC_TMP/pool.token" WEB_BUILD=$build \
WEB_SHOTS=$shots WEB_TMP=$SVC_TMP WEB_OTHER_JOB=$bob_job \
	node tests/web/dashboard.mjs 2> "$SVC_TMP/node.err"
status=$?
[ -s "$SVC_TMP/node.err" ] && sed 's/^/  node: /' "$SVC_TMP/node.err" | tail -20
check web_browser_script_ran "$status" "dashboard.mjs exited with status $status"
# the server's log was kept for the token-leak check (tests/service/token_leak_check.sh)
grep -q 'route=/ ' "$SVC_TMP/main.err"
check web_pages_served_by_poro_server $? "no request for / in the server's log"
